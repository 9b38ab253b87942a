// Scene files: every shipped scene loads; every kind of malformed file is refused with an
// error naming file, line and field; the scripted trajectory is sampled as documented.
#include "fissure/host_sim/scene_loader.hpp"

#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tet_test_meshes.hpp"

namespace fissure::host {
namespace {

// Tests run in the source tree (fissure_add_test's WORKING_DIRECTORY).
const std::filesystem::path kScenes = "scenes";

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// 1-based line of the first occurrence of `needle` in `text`.
int line_of(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += text[i] == '\n' ? 1 : 0;
  return line;
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Loads `text` and returns the SceneError (fails the test when it loads).
SceneError load_error(const std::string& text) {
  try {
    (void)load_scene_text(text, "bad.toml", kScenes);
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "the malformed scene loaded";
  return SceneError("", 0, "", "");
}

void expect_error(const SceneError& e, int line, const std::string& field, const std::string& message_part) {
  EXPECT_EQ(e.file(), "bad.toml");
  EXPECT_EQ(e.line(), line) << e.what();
  EXPECT_EQ(e.field(), field) << e.what();
  EXPECT_NE(std::string(e.what()).find("bad.toml:" + std::to_string(line) + ":"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find(message_part), std::string::npos) << e.what();
}

TEST(SceneLoader, EveryShippedSceneLoads) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kScenes)) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().string());
    const SceneDescription scene = load_scene(entry.path());
    EXPECT_EQ(scene.name, entry.path().stem().string());
    EXPECT_FALSE(scene.description.empty());
    EXPECT_FALSE(scene.trajectory.waypoints.empty());
    EXPECT_GT(trajectory_duration_s(scene), 0.0);
    ++count;
  }
  EXPECT_GE(count, 4);
}

TEST(SceneLoader, PaperScenesHaveTheirShapes) {
  const SceneDescription spatula = load_scene(resolve_scene_path("spatula-sphere"));
  EXPECT_EQ(spatula.tool.kind, ToolKind::kBox);
  ASSERT_TRUE(std::holds_alternative<SoftSphere>(spatula.soft_bodies.front().shape));
  EXPECT_EQ(std::get<SoftSphere>(spatula.soft_bodies.front().shape).faces_count, 128);
  EXPECT_DOUBLE_EQ(std::get<SoftSphere>(spatula.soft_bodies.front().shape).radius_m, 0.05);
  EXPECT_EQ(spatula.simulation.collision_method, SceneCollisionMethod::kPaired);
  EXPECT_FALSE(spatula.device_mapping.clamp_mode);
  EXPECT_EQ(spatula.hand.waypoints.size(), 2u);

  const SceneDescription convex = load_scene(resolve_scene_path("convex-spatula-sphere"));
  EXPECT_EQ(convex.tool.kind, ToolKind::kConvexMesh);
  EXPECT_GT(convex.tool.mesh_triangles.size(), 100u);
  EXPECT_DOUBLE_EQ(convex.tool.pairing_ray_limit_m, 0.003);

  const SceneDescription clamp = load_scene(resolve_scene_path("clamp-sphere.toml"));
  EXPECT_EQ(clamp.tool.kind, ToolKind::kClamp);
  EXPECT_TRUE(clamp.device_mapping.clamp_mode);
  EXPECT_EQ(clamp.device_mapping.closing_axis_world, 2);

  const SceneDescription vessel = load_scene(resolve_scene_path("clamp-vessel"));
  EXPECT_TRUE(std::holds_alternative<SoftCylinder>(vessel.soft_bodies.front().shape));
}

TEST(SceneLoader, UnknownKeyNamesFileLineAndField) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  const std::string bad = replace(good, "mass_kg = 0.1\n", "mass_kg = 0.1\ncolour = \"red\"\n");
  expect_error(load_error(bad), line_of(bad, "colour"), "soft_body.colour", "unknown key");
}

TEST(SceneLoader, MissingFieldNamesItsTable) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  const std::string bad = replace(good, "mass_kg = 0.1\n", "");
  expect_error(load_error(bad), line_of(bad, "[soft_body]"), "soft_body.mass_kg", "missing field");
}

TEST(SceneLoader, MissingTableIsNamed) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  const std::string bad = replace(good, "[ground]", "[grund]");
  const SceneError e = load_error(bad);
  EXPECT_EQ(e.field(), "ground");
  EXPECT_NE(std::string(e.what()).find("missing table"), std::string::npos) << e.what();
}

TEST(SceneLoader, WrongUnitIsNamedAsSuch) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  const std::string bad = replace(good, "radius_m = 0.05", "radius_mm = 50");
  expect_error(load_error(bad), line_of(bad, "radius_mm"), "soft_body.radius_mm", "wrong unit");
  // Hunt-Crossley per-unit-area stiffness given in per-triangle units.
  const std::string bad_hc = replace(good, "stiffness_pa_per_m_pow_n", "stiffness_n_per_m_pow_n");
  expect_error(load_error(bad_hc), line_of(bad_hc, "stiffness_n_per_m_pow_n"), "hunt_crossley.stiffness_n_per_m_pow_n", "wrong unit");
  // A unit in the value instead of the key is not a number.
  const std::string bad_value = replace(good, "time_step_s = 0.001", "time_step_s = \"1 ms\"");
  expect_error(load_error(bad_value), line_of(bad_value, "time_step_s"), "simulation.time_step_s", "expected a number in seconds");
}

TEST(SceneLoader, OutOfRangeValueNamesField) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  const std::string bad = replace(good, "linear_stiffness_ratio = 1.0", "linear_stiffness_ratio = 2.0");
  expect_error(load_error(bad), line_of(bad, "linear_stiffness_ratio"), "soft_body.linear_stiffness_ratio", "must be in");
  // A host step at which the shipped bodies turn inside out (0.01 s) is refused before anything
  // runs; the largest that works (0.005 s) loads.
  const std::string coarse = replace(good, "time_step_s = 0.001 ", "time_step_s = 0.01  ");
  expect_error(load_error(coarse), line_of(coarse, "time_step_s"), "simulation.time_step_s", "must be in [1e-06, 0.005] (got 0.01)");
  EXPECT_NO_THROW((void)load_scene_text(replace(good, "time_step_s = 0.001 ", "time_step_s = 0.005 "), "ok.toml", kScenes));
  const std::string bad_method = replace(good, "collision_method = \"paired\"", "collision_method = \"magic\"");
  expect_error(load_error(bad_method), line_of(bad_method, "collision_method"), "simulation.collision_method",
               "'magic' is not one of: paired, ray, bullet");
}

// The one name table for collision methods: scene files, `fissure sim --method` and
// `fissure render --method` all read names through it.
TEST(SceneLoader, CollisionMethodNamesParseBackAndNothingElseDoes) {
  for (const SceneCollisionMethod method : kCollisionMethods) EXPECT_EQ(parse_collision_method(to_string(method)), method);
  EXPECT_STREQ(to_string(SceneCollisionMethod::kPaired), "paired");
  EXPECT_STREQ(to_string(SceneCollisionMethod::kRay), "ray");
  EXPECT_STREQ(to_string(SceneCollisionMethod::kBullet), "bullet");
  EXPECT_EQ(parse_collision_method("magic"), std::nullopt);
  EXPECT_EQ(parse_collision_method(""), std::nullopt);
  EXPECT_EQ(parse_collision_method("Paired"), std::nullopt);
}

// [simulation] contact_response: optional (after_step, the paper's order), "in_solver" read, any
// other text refused with its line and the names that work.
TEST(SceneLoader, ContactResponseIsOptionalAndChecked) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  EXPECT_EQ(load_scene_text(good, "good.toml", kScenes).simulation.contact_response, ContactResponse::kAfterStep);
  const std::string in_solver = replace(good, "collision_method = \"paired\"", "collision_method = \"paired\"\ncontact_response = \"in_solver\"");
  EXPECT_EQ(load_scene_text(in_solver, "in_solver.toml", kScenes).simulation.contact_response, ContactResponse::kInSolver);
  const std::string bad = replace(good, "collision_method = \"paired\"", "collision_method = \"paired\"\ncontact_response = \"inside\"");
  expect_error(load_error(bad), line_of(bad, "contact_response"), "simulation.contact_response", "'inside' is not one of: after_step, in_solver");
  for (const ContactResponse r : {ContactResponse::kAfterStep, ContactResponse::kInSolver}) EXPECT_EQ(parse_contact_response(to_string(r)), r);
  EXPECT_EQ(parse_contact_response("In_Solver"), std::nullopt);
}

// [tool] friction_static_ratio / friction_kinetic_ratio: optional (0: frictionless), kinetic
// defaults to static, each in [0, 2], kinetic ≤ static, and only with the in-solver response (the
// friction is solved in its iterations).
TEST(SceneLoader, ToolFrictionIsOptionalCheckedAndNeedsTheInSolverResponse) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  const SceneDescription plain = load_scene_text(good, "good.toml", kScenes);
  EXPECT_EQ(plain.tool.friction_static_ratio, 0.0);
  EXPECT_EQ(plain.tool.friction_kinetic_ratio, 0.0);
  const std::string in_solver = replace(good, "collision_method = \"paired\"", "collision_method = \"paired\"\ncontact_response = \"in_solver\"");
  const std::string both = replace(in_solver, "node_spacing_m = 0.003", "node_spacing_m = 0.003\nfriction_static_ratio = 0.5\nfriction_kinetic_ratio = 0.4");
  const SceneDescription gripping = load_scene_text(both, "both.toml", kScenes);
  EXPECT_EQ(gripping.tool.friction_static_ratio, 0.5);
  EXPECT_EQ(gripping.tool.friction_kinetic_ratio, 0.4);
  const std::string static_only = replace(in_solver, "node_spacing_m = 0.003", "node_spacing_m = 0.003\nfriction_static_ratio = 0.3");
  EXPECT_EQ(load_scene_text(static_only, "static.toml", kScenes).tool.friction_kinetic_ratio, 0.3);
  const std::string too_high = replace(in_solver, "node_spacing_m = 0.003", "node_spacing_m = 0.003\nfriction_static_ratio = 5");
  expect_error(load_error(too_high), line_of(too_high, "friction_static_ratio"), "tool.friction_static_ratio", "must be in [0, 2] (got 5)");
  const std::string kinetic_above = replace(in_solver, "node_spacing_m = 0.003", "node_spacing_m = 0.003\nfriction_static_ratio = 0.2\nfriction_kinetic_ratio = 0.4");
  expect_error(load_error(kinetic_above), line_of(kinetic_above, "friction_kinetic_ratio"), "tool.friction_kinetic_ratio", "must be <= friction_static_ratio (0.2)");
  const std::string after_step = replace(good, "node_spacing_m = 0.003", "node_spacing_m = 0.003\nfriction_static_ratio = 0.5");
  expect_error(load_error(after_step), line_of(after_step, "friction_static_ratio"), "tool.friction_static_ratio", "contact_response = \"in_solver\"");
  // The contact's viscous shear: the film default, a value of the user's, its range, and no
  // damping without friction.
  EXPECT_EQ(gripping.tool.friction_shear_damping_pa_s_per_m, kTissueFilmShearDamping_pa_s_per_m);
  const std::string damped = replace(both, "friction_kinetic_ratio = 0.4", "friction_kinetic_ratio = 0.4\nfriction_shear_damping_pa_s_per_m = 2500");
  EXPECT_EQ(load_scene_text(damped, "damped.toml", kScenes).tool.friction_shear_damping_pa_s_per_m, 2500.0);
  const std::string absurd = replace(both, "friction_kinetic_ratio = 0.4", "friction_kinetic_ratio = 0.4\nfriction_shear_damping_pa_s_per_m = -1");
  expect_error(load_error(absurd), line_of(absurd, "friction_shear_damping"), "tool.friction_shear_damping_pa_s_per_m", "must be in [0, 1e+06] (got -1)");
  const std::string dry_damped = replace(in_solver, "node_spacing_m = 0.003", "node_spacing_m = 0.003\nfriction_shear_damping_pa_s_per_m = 1000");
  expect_error(load_error(dry_damped), line_of(dry_damped, "friction_shear_damping"), "tool.friction_shear_damping_pa_s_per_m", "needs friction");
  const std::string wrong_unit = replace(both, "friction_kinetic_ratio = 0.4", "friction_kinetic_ratio = 0.4\nfriction_shear_damping_n_s_per_m = 1");
  expect_error(load_error(wrong_unit), line_of(wrong_unit, "friction_shear_damping_n"), "tool.friction_shear_damping_n_s_per_m", "wrong unit");
}

TEST(SceneLoader, ShapeMatchingIsOptionalAndRangeChecked) {
  const std::string shipped = read(kScenes / "spatula-sphere.toml");
  EXPECT_EQ(load_scene_text(shipped, "good.toml", kScenes).soft_bodies.front().shape_matching_ratio, 0.05);
  // Without the (optional) key: its line, comment and all, removed.
  const std::size_t key = shipped.find("shape_matching_ratio");
  ASSERT_NE(key, std::string::npos);
  const std::size_t next_key = shipped.find("damping_ratio", key);
  const std::string good = shipped.substr(0, key) + shipped.substr(next_key);
  EXPECT_EQ(load_scene_text(good, "good.toml", kScenes).soft_bodies.front().shape_matching_ratio, 0.0);
  const std::string with = replace(good, "damping_ratio = 0.02", "damping_ratio = 0.02\nshape_matching_ratio = 0.05");
  EXPECT_EQ(load_scene_text(with, "good.toml", kScenes).soft_bodies.front().shape_matching_ratio, 0.05);
  const std::string bad = replace(good, "damping_ratio = 0.02", "damping_ratio = 0.02\nshape_matching_ratio = 1.5");
  expect_error(load_error(bad), line_of(bad, "shape_matching_ratio"), "soft_body.shape_matching_ratio", "must be in");
}

// Bending links (soft_bending_links.hpp): optional, off by default; the stiffness is a Bullet
// ratio in [0, 1], the distance an edge count in [2, kMaxBendingDistance] that means nothing
// without the links, so it is refused alone rather than silently ignored.
TEST(SceneLoader, BendingLinksAreOptionalAndRangeChecked) {
  const std::string good = read(kScenes / "clamp-sphere.toml");
  ASSERT_EQ(good.find("bending_"), std::string::npos) << "a scene without bending links";
  const SoftBodyDescription plain = load_scene_text(good, "good.toml", kScenes).soft_bodies.front();
  EXPECT_EQ(plain.bending_stiffness_ratio, 0.0);
  EXPECT_EQ(plain.bending_distance_count, 2);
  const std::string with = replace(good, "damping_ratio = 0.02", "damping_ratio = 0.02\nbending_stiffness_ratio = 0.3\nbending_distance_count = 3");
  const SoftBodyDescription bent = load_scene_text(with, "good.toml", kScenes).soft_bodies.front();
  EXPECT_EQ(bent.bending_stiffness_ratio, 0.3);
  EXPECT_EQ(bent.bending_distance_count, 3);

  const std::string stiff = replace(with, "bending_stiffness_ratio = 0.3", "bending_stiffness_ratio = 1.5");
  expect_error(load_error(stiff), line_of(stiff, "bending_stiffness_ratio"), "soft_body.bending_stiffness_ratio", "must be in [0, 1] (got 1.5)");
  const std::string negative = replace(with, "bending_stiffness_ratio = 0.3", "bending_stiffness_ratio = -0.1");
  expect_error(load_error(negative), line_of(negative, "bending_stiffness_ratio"), "soft_body.bending_stiffness_ratio", "must be in [0, 1] (got -0.1)");
  const std::string near = replace(with, "bending_distance_count = 3", "bending_distance_count = 1");
  expect_error(load_error(near), line_of(near, "bending_distance_count"), "soft_body.bending_distance_count", "must be in [2, 4] (got 1)");
  const std::string far = replace(with, "bending_distance_count = 3", "bending_distance_count = 5");
  expect_error(load_error(far), line_of(far, "bending_distance_count"), "soft_body.bending_distance_count", "must be in [2, 4] (got 5)");
  const std::string fractional = replace(with, "bending_distance_count = 3", "bending_distance_count = 2.5");
  expect_error(load_error(fractional), line_of(fractional, "bending_distance_count"), "soft_body.bending_distance_count", "expected an integer");
  const std::string alone = replace(with, "bending_stiffness_ratio = 0.3\n", "");
  expect_error(load_error(alone), line_of(alone, "bending_distance_count"), "soft_body.bending_distance_count",
               "has no effect without bending links: set bending_stiffness_ratio > 0");
  const std::string wrong_unit = replace(with, "bending_stiffness_ratio = 0.3", "bending_stiffness_pa = 0.3");
  expect_error(load_error(wrong_unit), line_of(wrong_unit, "bending_stiffness_pa"), "soft_body.bending_stiffness_pa", "wrong unit");
  // A shell's links only: an FEM body has no links to add them to, and refuses the key as it
  // refuses the other Bullet ratios.
  const std::string fem = replace(read(kScenes / "spatula-fem-lobe.toml"), "model = \"fem\"", "model = \"fem\"\nbending_stiffness_ratio = 0.3");
  expect_error(load_error(fem), line_of(fem, "bending_stiffness_ratio"), "soft_body.bending_stiffness_ratio", "unknown key");
}

// Bullet's pose matching collapses a body whose rest pose matrix it cannot decompose
// (kPoseMatchingMinNormProduct_m4): the paper's ball at 30 mm radius is refused where the key
// is, with the body's radius of gyration; at 32 mm, or without pose matching, it loads.
TEST(SceneLoader, PoseMatchingOnABodyTooSmallForBulletIsRefused) {
  const std::string shipped = read(kScenes / "spatula-sphere.toml");
  const std::string small = replace(shipped, "radius_m = 0.05", "radius_m = 0.03");
  expect_error(load_error(small), line_of(small, "shape_matching_ratio"), "soft_body.shape_matching_ratio",
               "too small for Bullet's pose matching: its rest radius of gyration is 30.0 mm");
  EXPECT_EQ(load_scene_text(replace(shipped, "radius_m = 0.05", "radius_m = 0.032"), "good.toml", kScenes).soft_bodies.size(), 1u);
  EXPECT_EQ(load_scene_text(replace(small, "shape_matching_ratio = 0.05", "shape_matching_ratio = 0.0"), "good.toml", kScenes)
                .soft_bodies.front()
                .shape_matching_ratio,
            0.0);
}

// [[soft_body.anchor]] goes right after the [soft_body] table (before [tool]).
std::string with_anchor(const std::string& shipped, const std::string& anchor_body) {
  return replace(shipped, "\n[tool]\n", "\n[[soft_body.anchor]]\n" + anchor_body + "\n\n[tool]\n");
}

TEST(SceneLoader, AnchorsAreOptionalAndRead) {
  const std::string shipped = read(kScenes / "spatula-sphere.toml");
  EXPECT_TRUE(load_scene_text(shipped, "good.toml", kScenes).soft_bodies.front().anchors.empty());
  const std::string good = with_anchor(shipped, "min_world_m = [-0.1, -0.01, -0.1]\nmax_world_m = [0.1, 0.012, 0.1]");
  const SceneDescription scene = load_scene_text(good, "good.toml", kScenes);
  ASSERT_EQ(scene.soft_bodies.front().anchors.size(), 1u);
  EXPECT_EQ(scene.soft_bodies.front().anchors[0].min_world_m[1], -0.01);
  EXPECT_EQ(scene.soft_bodies.front().anchors[0].max_world_m[1], 0.012);
}

TEST(SceneLoader, MalformedAnchorsNameFileLineAndField) {
  const std::string shipped = read(kScenes / "spatula-sphere.toml");
  const std::string unknown = with_anchor(shipped, "min_world_m = [-0.1, -0.01, -0.1]\nmax_world_m = [0.1, 0.012, 0.1]\nnode = 3");
  expect_error(load_error(unknown), line_of(unknown, "node = 3"), "soft_body.anchor[0].node", "unknown key");
  const std::string unit = with_anchor(shipped, "min_world_mm = [-100, -10, -100]\nmax_world_m = [0.1, 0.012, 0.1]");
  expect_error(load_error(unit), line_of(unit, "min_world_mm"), "soft_body.anchor[0].min_world_mm", "wrong unit");
  const std::string missing = with_anchor(shipped, "min_world_m = [-0.1, -0.01, -0.1]");
  expect_error(load_error(missing), line_of(missing, "[[soft_body.anchor]]"), "soft_body.anchor[0].max_world_m", "missing field");
  const std::string short_vec = with_anchor(shipped, "min_world_m = [-0.1, -0.01]\nmax_world_m = [0.1, 0.012, 0.1]");
  expect_error(load_error(short_vec), line_of(short_vec, "min_world_m"), "soft_body.anchor[0].min_world_m", "array of 3 numbers");
  const std::string inverted = with_anchor(shipped, "min_world_m = [-0.1, 0.02, -0.1]\nmax_world_m = [0.1, 0.012, 0.1]");
  expect_error(load_error(inverted), line_of(inverted, "max_world_m"), "soft_body.anchor[0].max_world_m", "must be >= min_world_m");
  // A box beside the ball (above it: the top is at y = 0.102) selects no node: a typo, refused.
  const std::string empty = with_anchor(shipped, "min_world_m = [-0.1, 0.2, -0.1]\nmax_world_m = [0.1, 0.3, 0.1]");
  expect_error(load_error(empty), line_of(empty, "[[soft_body.anchor]]"), "soft_body.anchor[0]", "selects no soft node");
  const std::string not_table = replace(shipped, "collision_margin_m = 0.002", "collision_margin_m = 0.002\nanchor = 1");
  expect_error(load_error(not_table), line_of(not_table, "anchor = 1"), "soft_body.anchor", "array of tables");
}

// [[soft_body]]: several bodies, each read as the single [soft_body] table, anchors inside each.
TEST(SceneLoader, SeveralSoftBodiesAreReadEachWithItsAnchors) {
  const SceneDescription fissure = load_scene(kScenes / "spatula-fissure.toml");
  ASSERT_EQ(fissure.soft_bodies.size(), 2u);
  for (std::size_t b = 0; b < 2; ++b) {
    SCOPED_TRACE(b);
    const SoftBodyDescription& body = fissure.soft_bodies[b];
    ASSERT_TRUE(std::holds_alternative<SoftMesh>(body.shape));
    EXPECT_EQ(std::get<SoftMesh>(body.shape).triangles.size(), 1280u);
    ASSERT_EQ(body.anchors.size(), 1u);
    EXPECT_DOUBLE_EQ(body.mass_kg, 0.1);
  }
  EXPECT_DOUBLE_EQ(std::get<SoftMesh>(fissure.soft_bodies[0].shape).offset_world_m[0], -0.0505);
  EXPECT_DOUBLE_EQ(std::get<SoftMesh>(fissure.soft_bodies[1].shape).offset_world_m[0], 0.0505);
  EXPECT_DOUBLE_EQ(fissure.soft_bodies[0].anchors[0].max_world_m[0], 0.0);
  EXPECT_DOUBLE_EQ(fissure.soft_bodies[1].anchors[0].min_world_m[0], 0.0);
  // The single-table form is one body.
  EXPECT_EQ(load_scene(kScenes / "spatula-sphere.toml").soft_bodies.size(), 1u);
}

TEST(SceneLoader, ABadValueInTheSecondSoftBodyNamesThatBody) {
  const std::string good = read(kScenes / "spatula-fissure.toml");
  const std::string right_lobe = "offset_world_m = [0.0505, 0.02075, 0.0]\nmass_kg = 0.1\nlinear_stiffness_ratio = 1.0";
  const std::string stiff = replace(good, right_lobe, "offset_world_m = [0.0505, 0.02075, 0.0]\nmass_kg = 0.1\nlinear_stiffness_ratio = 2.0");
  expect_error(load_error(stiff), line_of(stiff, "linear_stiffness_ratio = 2.0"), "soft_body[1].linear_stiffness_ratio", "must be in");
  const std::string unknown = replace(good, right_lobe, right_lobe + "\nyoungs_modulus = 3000");
  expect_error(load_error(unknown), line_of(unknown, "youngs_modulus"), "soft_body[1].youngs_modulus", "unknown key");
  // The right lobe's anchor box moved above both lobes selects none of its nodes.
  const std::string empty = replace(good, "min_world_m = [0.0, -0.01, -0.04]\nmax_world_m = [0.11, 0.012, 0.04]",
                                    "min_world_m = [0.0, 0.2, -0.04]\nmax_world_m = [0.11, 0.3, 0.04]");
  expect_error(load_error(empty), line_of(empty, "min_world_m = [0.0, 0.2") - 1, "soft_body[1].anchor[0]", "selects no soft node");
}

TEST(SceneLoader, MoreSoftBodiesThanTheLimitAreRefused) {
  const std::string sphere = read(kScenes / "spatula-sphere.toml");
  const std::size_t begin = sphere.find("[soft_body]");
  const std::size_t end = sphere.find("[tool]");
  ASSERT_NE(begin, std::string::npos);
  // The sphere's [soft_body] table as one [[soft_body]] entry.
  const std::size_t header = std::string("[soft_body]").size();
  const std::string table = "[[soft_body]]" + sphere.substr(begin + header, end - begin - header);
  std::string bodies;
  for (int i = 0; i <= kMaxSoftBodies; ++i) bodies += table;
  const std::string many = sphere.substr(0, begin) + bodies + sphere.substr(end);
  expect_error(load_error(many), line_of(many, "[[soft_body]]"), "soft_body", "1 to " + std::to_string(kMaxSoftBodies) + " soft bodies (got 9)");
  std::string eight;
  for (int i = 0; i < kMaxSoftBodies; ++i) eight += table;
  EXPECT_EQ(load_scene_text(sphere.substr(0, begin) + eight + sphere.substr(end), "ok.toml", kScenes).soft_bodies.size(),
            static_cast<std::size_t>(kMaxSoftBodies));
}

TEST(SceneLoader, DeformationMeasureIsOptionalAndChecked) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  EXPECT_EQ(load_scene_text(good, "good.toml", kScenes).hunt_crossley.measure, DeformationMeasure::kNormalDisplacement);
  const std::string paper = replace(good, "exponent_n = 1.5", "exponent_n = 1.5\ndeformation_measure = \"centroid_distance\"");
  EXPECT_EQ(load_scene_text(paper, "good.toml", kScenes).hunt_crossley.measure, DeformationMeasure::kCentroidDistance);
  const std::string bad = replace(good, "exponent_n = 1.5", "exponent_n = 1.5\ndeformation_measure = \"centroid\"");
  expect_error(load_error(bad), line_of(bad, "deformation_measure"), "hunt_crossley.deformation_measure", "not one of");
}

TEST(SceneLoader, UnreadableMeshNamesMeshPath) {
  const std::string good = read(kScenes / "convex-spatula-sphere.toml");
  const std::string missing = replace(good, "meshes/convex-spatula.obj", "meshes/no-such-mesh.obj");
  expect_error(load_error(missing), line_of(missing, "mesh_path"), "tool.mesh_path", "unreadable mesh");

  // A readable OBJ that is not a closed convex mesh (one triangle) is refused too.
  const auto dir = std::filesystem::temp_directory_path() / "fissure_scene_loader_test";
  std::filesystem::create_directories(dir);
  {
    std::ofstream obj(dir / "open.obj");
    obj << "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n";
  }
  const std::string open = replace(good, "meshes/convex-spatula.obj", (dir / "open.obj").string());
  expect_error(load_error(open), line_of(open, "mesh_path"), "tool.mesh_path", "unreadable mesh");
}

TEST(SceneLoader, MeshPathsThatAreNoMeshAreNamedInTheMeshsTerms) {
  const std::string good = read(kScenes / "convex-spatula-sphere.toml");
  const auto dir = std::filesystem::temp_directory_path() / "fissure_scene_loader_mesh_terms";
  std::filesystem::create_directories(dir / "a-directory.obj");
  // A directory: said so, not "fewer than 4 vertices".
  const std::string directory = replace(good, "meshes/convex-spatula.obj", (dir / "a-directory.obj").string());
  expect_error(load_error(directory), line_of(directory, "mesh_path"), "tool.mesh_path", "is a directory, not an OBJ file");
  // A NaN coordinate: the OBJ line, the vertex and the value, not "not convex".
  std::string obj = read(kScenes / "meshes" / "convex-spatula.obj");
  const std::size_t first_v = obj.find("\nv ") + 1;
  const std::size_t end_of_line = obj.find('\n', first_v);
  obj.replace(first_v, end_of_line - first_v, "v 0.029 nan 0.0045");
  std::ofstream(dir / "nan.obj") << obj;
  const std::string nan = replace(good, "meshes/convex-spatula.obj", (dir / "nan.obj").string());
  const SceneError e = load_error(nan);
  expect_error(e, line_of(nan, "mesh_path"), "tool.mesh_path", "nan.obj' line 2: vertex 1 coordinate y is 'nan', not a finite number");
  EXPECT_EQ(std::string(e.what()).find("convex"), std::string::npos) << e.what();
  // Too few elements: both counts.
  std::ofstream(dir / "two.obj") << "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n";
  const std::string two = replace(good, "meshes/convex-spatula.obj", (dir / "two.obj").string());
  expect_error(load_error(two), line_of(two, "mesh_path"), "tool.mesh_path", "the mesh has 3 vertices and 1 triangles");
  std::filesystem::remove_all(dir);
}

TEST(SceneLoader, AClampWithoutStartOrLegJawGapsKeepsThemOpen) {
  // Both are optional: absent, the jaws start fully open and a leg keeps the gap it has.
  const std::string good = read(kScenes / "clamp-vessel.toml");
  std::string without = replace(good, "start_jaw_gap_m = 0.05\n", "");
  without = replace(without, "jaw_gap_m = 0.05\n", "");
  const SceneDescription scene = load_scene_text(without, "clamp.toml", kScenes);
  EXPECT_EQ(scene.trajectory.start_jaw_gap_m, -1.0);
  EXPECT_EQ(scene.trajectory.waypoints.back().jaw_gap_m, -1.0);
  const std::string negative = replace(good, "start_jaw_gap_m = 0.05", "start_jaw_gap_m = -0.01");
  expect_error(load_error(negative), line_of(negative, "start_jaw_gap_m"), "trajectory.start_jaw_gap_m", "must be in [0, 10] (got -0.01)");
}

TEST(SceneLoader, BadTomlSyntaxNamesLine) {
  const std::string good = read(kScenes / "spatula-sphere.toml");
  const std::string bad = replace(good, "radius_m = 0.05", "radius_m = = 0.05");
  const SceneError e = load_error(bad);
  EXPECT_EQ(e.line(), line_of(bad, "radius_m = = 0.05"));
  EXPECT_NE(std::string(e.what()).find("bad.toml:"), std::string::npos);
  EXPECT_NE(std::string(e.what()).find("TOML syntax error"), std::string::npos) << e.what();
}

TEST(SceneLoader, UnreadableFileAndUnknownSceneName) {
  EXPECT_THROW((void)load_scene("scenes/definitely-not-here.toml"), SceneError);
  EXPECT_THROW((void)resolve_scene_path("definitely-not-a-scene"), SceneError);
  EXPECT_EQ(resolve_scene_path("clamp-vessel").filename(), "clamp-vessel.toml");
}

TEST(SceneLoader, ClampSceneNeedsClampMode) {
  const std::string good = read(kScenes / "clamp-sphere.toml");
  const std::string bad = replace(good, "clamp_mode = true", "clamp_mode = false");
  expect_error(load_error(bad), line_of(bad, "clamp_mode = false"), "device_mapping.clamp_mode", "clamp_mode = true");
}

TEST(SceneTrajectory, LegsAndHoldsAreSampledLinearly) {
  SceneDescription scene = load_scene(kScenes / "spatula-sphere.toml");
  // start y 0.12 → 0.092 at 0.05 m/s (0.56 s), hold 0.5 s, → 0.12 (0.56 s), hold 0.1 s.
  EXPECT_NEAR(trajectory_duration_s(scene), 0.56 + 0.5 + 0.56 + 0.1, 1e-9);
  EXPECT_NEAR(sample_trajectory(scene, 0.0).pose.position_world_m[1], 0.12, 1e-12);
  EXPECT_NEAR(sample_trajectory(scene, 0.28).pose.position_world_m[1], 0.106, 1e-9);
  EXPECT_NEAR(sample_trajectory(scene, 0.8).pose.position_world_m[1], 0.092, 1e-12);
  EXPECT_NEAR(sample_trajectory(scene, 1.06 + 0.28).pose.position_world_m[1], 0.106, 1e-9);
  EXPECT_NEAR(sample_trajectory(scene, 100.0).pose.position_world_m[1], 0.12, 1e-12);

  // The clamp's jaw gap closes over the leg at the leg's speed.
  const SceneDescription clamp = load_scene(kScenes / "clamp-sphere.toml");
  EXPECT_NEAR(sample_trajectory(clamp, 0.0).jaw_gap_m, 0.12, 1e-12);
  EXPECT_NEAR(sample_trajectory(clamp, 1.0).jaw_gap_m, 0.10, 1e-9);   // 0.02 m/s for 1 s
  // closed to 0.093 after 0.027 m / 0.02 m/s = 1.35 s, held 0.5 s
  EXPECT_NEAR(sample_trajectory(clamp, 1.6).jaw_gap_m, 0.093, 1e-12);
}

}  // namespace
}  // namespace fissure::host

namespace fissure::host {
namespace {

// [soft_body] model = "fem" (issue 24): the SI material keys on a tetrahedral mesh.
class FemSceneLoader : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("fissure-fem-scene-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    test_tets::write_vtk(test_tets::kuhn_box({2, 1, 2}, 0.01), dir_ / "block.vtk");
    shell_ = read(kScenes / "spatula-blob.toml");
    shell_ = replace(shell_, "\"meshes/organ-blob.obj\"", "\"" + (dir_ / "block.vtk").string() + "\"");
    // A 2 cm block is too small for Bullet's pose matching (the loader refuses it as a shell).
    shell_ = replace(shell_, "shape_matching_ratio = 0.05", "shape_matching_ratio = 0.0");
    // The lobe's bed box lies below the block, and an FEM body takes the after_step response,
    // which has no tool friction.
    const std::size_t bed = shell_.find("[[soft_body.anchor]]");
    shell_.erase(bed, shell_.find("[tool]") - bed);
    shell_ = replace(shell_, "contact_response = \"in_solver\"", "contact_response = \"after_step\"");
    const std::size_t friction = shell_.find("friction_static_ratio = 0.5");
    shell_.erase(friction, shell_.find("[hunt_crossley]") - friction);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // The blob scene's [soft_body] with its shell keys replaced by the FEM ones (`material`).
  std::string fem_scene(const std::string& material) const {
    std::string text = shell_;
    const std::size_t from = text.find("mass_kg = 0.1"), to = text.find("[tool]");
    text.replace(from, to - from, "model = \"fem\"\n" + material + "friction_ratio = 0.2\ncollision_margin_m = 0.002\n\n");
    return text;
  }

  std::filesystem::path dir_;
  std::string shell_;
};

const std::string kLiver = "youngs_modulus_pa = 7000.0\npoisson_ratio = 0.45\ndensity_kg_per_m3 = 1040.0\n";

TEST_F(FemSceneLoader, ReadsTheSiMaterialAndTheMassFromDensityAndVolume) {
  const SceneDescription scene = load_scene_text(fem_scene(kLiver + "elasticity = \"neo_hookean\"\nmass_damping_per_s = 5.0\n"), "good.toml", kScenes);
  EXPECT_EQ(scene.soft_bodies.front().model, SoftBodyModel::kFem);
  EXPECT_EQ(scene.soft_bodies.front().fem.model, FemModel::kNeoHookean);
  EXPECT_EQ(scene.soft_bodies.front().fem.youngs_modulus_pa, 7000.0);
  EXPECT_EQ(scene.soft_bodies.front().fem.poisson_ratio, 0.45);
  EXPECT_EQ(scene.soft_bodies.front().fem.density_kg_per_m3, 1040.0);
  EXPECT_EQ(scene.soft_bodies.front().fem.mass_damping_per_s, 5.0);
  EXPECT_EQ(scene.soft_bodies.front().fem.stiffness_damping_s, 0.0);
  EXPECT_NEAR(scene.soft_bodies.front().mass_kg, 1040.0 * 0.02 * 0.01 * 0.02, 1e-12);
  // The defaults: a shell unless told otherwise, corotated linear elasticity.
  EXPECT_EQ(load_scene_text(shell_, "good.toml", kScenes).soft_bodies.front().model, SoftBodyModel::kShell);
  EXPECT_EQ(load_scene_text(fem_scene(kLiver), "good.toml", kScenes).soft_bodies.front().fem.model, FemModel::kCorotatedSmoothed);
}

TEST_F(FemSceneLoader, OutOfRangeMaterialNamesFileLineFieldValueAndRange) {
  const std::string soft = fem_scene(replace(kLiver, "youngs_modulus_pa = 7000.0", "youngs_modulus_pa = 7.0"));
  expect_error(load_error(soft), line_of(soft, "youngs_modulus_pa = 7.0"), "soft_body.youngs_modulus_pa", "must be in [10, 1e+07] (got 7)");
  const std::string incompressible = fem_scene(replace(kLiver, "poisson_ratio = 0.45", "poisson_ratio = 0.5"));
  expect_error(load_error(incompressible), line_of(incompressible, "poisson_ratio = 0.5"), "soft_body.poisson_ratio", "must be in [0, 0.49] (got 0.5)");
  const std::string dense = fem_scene(replace(kLiver, "density_kg_per_m3 = 1040.0", "density_kg_per_m3 = 10400.0"));
  expect_error(load_error(dense), line_of(dense, "density_kg_per_m3 = 10400.0"), "soft_body.density_kg_per_m3", "must be in [100, 5000] (got 1.04e+04)");
  const std::string kpa = fem_scene(replace(kLiver, "youngs_modulus_pa = 7000.0", "youngs_modulus_kpa = 7.0"));
  expect_error(load_error(kpa), line_of(kpa, "youngs_modulus_kpa"), "soft_body.youngs_modulus_kpa", "wrong unit");
}

TEST_F(FemSceneLoader, ShellKeysAndSurfaceMeshesAreRefused) {
  const std::string with_shell_key = fem_scene(kLiver + "linear_stiffness_ratio = 1.0\n");
  expect_error(load_error(with_shell_key), line_of(with_shell_key, "linear_stiffness_ratio"), "soft_body.linear_stiffness_ratio", "unknown key");
  std::string surface = replace(fem_scene(kLiver), (dir_ / "block.vtk").string(), "meshes/organ-blob.obj");
  expect_error(load_error(surface), line_of(surface, "model = \"fem\""), "soft_body.model", "needs a volumetric body");
}

}  // namespace
}  // namespace fissure::host
