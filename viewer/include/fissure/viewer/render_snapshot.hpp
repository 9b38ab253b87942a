#pragma once
// What the view draws, split in two:
//   * RenderModel — the const *model* of a scene's picture, built ONCE after the soft body has
//     settled: soft triangles, the soft rest shape (for the deformation colour map), the tool
//     parts' meshes, the ground, where the camera looks. Handed to the view before it starts and
//     never changed while it runs.
//   * RenderSnapshot — the per-step *state*: soft node positions, tool/part poses, proxy patches,
//     the force on the tool and the overlay numbers. Fixed capacity and trivially copyable, so
//     the host publishes it through shared/'s wait-free LatestValueExchange: the view can never
//     block the host step or the rt tick, it only ever sees the newest complete snapshot.
// Positions are floats: the picture needs ~0.1 mm, and half the bytes halve the copy.
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/shared/latest_value_exchange.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::viewer {

/// Soft nodes a snapshot can hold. The paper scenes have 66 (sphere) … 386 (vessel) nodes; 4096
/// also covers the icosphere refinements up to 5120 faces (2562 nodes). 48 KiB of floats: a
/// publish is one memcpy of that (measured by `fissure render --measure`).
inline constexpr int kMaxSnapshotNodes = 4096;
/// Tool parts drawn per snapshot: the spatula, or the clamp's two jaws (host_sim's kMaxToolParts).
inline constexpr int kMaxSnapshotParts = host::kMaxToolParts;

struct SnapshotPose {
  std::array<float, 3> position_world_m{0.0F, 0.0F, 0.0F};
  std::array<float, 4> orientation_wxyz{1.0F, 0.0F, 0.0F, 0.0F};
};

/// One proxy contact patch as drawn: a small square on the zero-penetration plane.
struct SnapshotPatch {
  std::array<float, 3> point_world_m{0.0F, 0.0F, 0.0F};
  std::array<float, 3> normal_world{0.0F, 1.0F, 0.0F};
};

/// The overlay's numbers. NaN / negative means "not known here" (e.g. no rt loop in `fissure
/// render`): the overlay prints "-" for it.
struct OverlayNumbers {
  double time_s = 0.0;
  double tick_rate_hz = std::numeric_limits<double>::quiet_NaN();
  double force_n = 0.0;
  double proxy_age_ms = std::numeric_limits<double>::quiet_NaN();
  double host_step_ms = 0.0;
  std::int64_t overruns = -1;
  int crossed_nodes = 0;
  int contacts = 0;
  host::SceneCollisionMethod method = host::SceneCollisionMethod::kPaired;
  bool paused = false;
};

struct RenderSnapshot {
  std::uint64_t sequence = 0;  ///< +1 per capture; 0 = nothing captured yet
  int node_count = 0;
  std::array<std::array<float, 3>, kMaxSnapshotNodes> nodes_world_m{};
  SnapshotPose tool_pose{};  ///< the tool frame (the clamp handle hangs off it)
  int part_count = 0;
  std::array<SnapshotPose, kMaxSnapshotParts> part_poses{};
  int patch_count = 0;
  std::array<SnapshotPatch, kMaxContactPatches> patches{};
  std::array<float, 3> force_on_tool_world_n{0.0F, 0.0F, 0.0F};
  OverlayNumbers overlay{};
};
static_assert(std::is_trivially_copyable_v<RenderSnapshot>, "crosses threads through LatestValueExchange");

/// The exchange the host publishes into and one view (window or frame writer) reads from.
using SnapshotExchange = LatestValueExchange<RenderSnapshot>;

/// A triangle mesh in its own frame (float: it is only drawn).
struct DrawMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<int, 3>> triangles;  ///< counter-clockwise seen from outside
};

struct RenderModel {
  std::string scene_name;
  std::vector<std::array<int, 3>> soft_triangles;  ///< indices into the snapshot's nodes (CCW from outside)
  std::vector<Eigen::Vector3f> soft_rest_world_m;  ///< the settled shape: displacement from it is coloured
  /// Where each soft body's nodes start in soft_rest_world_m, and their total last: each body's
  /// rigid motion is fitted on its own (two lobes pushed apart each move as a whole).
  std::vector<int> soft_body_first_node{0};
  /// Displacement from the settled shape (its rigid motion taken out) drawn fully red [m]: 0.12
  /// of the soft body's smallest half-size (≈ 6 mm for the paper's 5 cm sphere: a 3 mm dent reads half-way to red, over
  /// twice as red as the rest of the ball, which the press squashes and pushes by ~1 mm; deeper
  /// presses saturate in the dent and the red area shows its extent). Plain displacement, not
  /// strain: Bullet's kLST = 1 links hardly stretch, the body bends instead.
  float deformation_full_scale_m = 0.006F;
  DrawMesh part_mesh;        ///< each collidable part (spatula box / convex mesh / one jaw), part frame
  bool has_handle = false;   ///< clamp: the handle box, tool frame (drawn, never collides)
  DrawMesh handle_mesh;
  float ground_top_y_m = 0.0F;
  Eigen::Vector2f ground_half_extents_m{0.5F, 0.5F};  ///< x, z
  Eigen::Vector3f focus_world_m = Eigen::Vector3f::Zero();  ///< where the default camera looks
  float focus_radius_m = 0.05F;                             ///< and how big the subject is
  /// Force arrow length per newton [m/N]: 20 N is one subject radius.
  float force_arrow_m_per_n = 0.0025F;
};

/// The rigid motion that carries the settled shape closest to the current nodes (least squares
/// over the nodes, Kabsch): p ≈ rotation · rest + translation.
struct RigidMotion {
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();
  Eigen::Vector3f translation = Eigen::Vector3f::Zero();
};

/// Fits the body's rigid motion from its settled shape to `nodes_world_m` (the first
/// min(count, rest nodes) nodes). The colour map takes it out: a body that slides or turns as a
/// whole is not deformed, and over a session a free body's drift (centimetres) would otherwise
/// outgrow the millimetre scale of a dent.
[[nodiscard]] RigidMotion fit_rigid_motion(const RenderModel& model, const Eigen::Vector3f* nodes_world_m, std::size_t count) noexcept;
/// The same over the nodes [first, end) alone (one body of several).
[[nodiscard]] RigidMotion fit_rigid_motion(const RenderModel& model, const Eigen::Vector3f* nodes_world_m, std::size_t first, std::size_t end) noexcept;

/// Where soft node `node`, now at `p_world_m`, sits on the deformation colour map: 0 where the
/// body's rigid motion carries its settled position (blue) → 1 at deformation_full_scale_m or
/// more from there (red).
[[nodiscard]] float deformation_fraction(const RenderModel& model, const RigidMotion& motion, std::size_t node,
                                         const Eigen::Vector3f& p_world_m) noexcept;

/// Builds the picture's model from a simulation whose soft body has settled (its current node
/// positions become the rest shape). Throws std::invalid_argument when the soft body has more
/// than kMaxSnapshotNodes nodes.
[[nodiscard]] RenderModel make_render_model(host::HostSimulation& sim);

/// Fills `out` from the simulation's last step: node positions, tool and part poses, the force,
/// crossed nodes / contacts / step time / method into the overlay (other overlay fields and the
/// patches are left as they are). noexcept, allocation-free; sequence += 1.
void capture_snapshot(const host::HostSimulation& sim, RenderSnapshot& out) noexcept;

/// Copies the proxy's patches into `out` (fissure run: the proxy rt_core is using).
void capture_patches(const ContactProxy& proxy, RenderSnapshot& out) noexcept;

}  // namespace fissure::viewer
