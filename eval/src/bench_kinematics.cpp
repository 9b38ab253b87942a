// `fissure bench kinematics --json FILE`: Falcon kinematics, run time against error.
//
// Point set: a hand trajectory sampled at 1 kHz (min-jerk moves between random waypoints in
// the workspace ball, peak speed 0.1–0.5 m/s, so consecutive samples are ≤ 0.5 mm apart).
// Warm FK starts every solve from the previous sample's solution — what the rt loop sees —
// never from the answer; cold FK starts from the workspace centre. For FK tolerances 1e-3 …
// 1e-12 rad: iterations, time per solve (median, p99) and position error (median, max).
// Baseline: libnifalcon's published scheme (falcon_hw/libnifalcon_reference.hpp) on the
// same points. Timing: steady_clock around batches of 64 consecutive solves (the clock
// read costs ~20–40 ns on this VM, more than a third of an IK), time per solve = batch
// time / 64; median and p99 are over batches pooled from all repeats.
#include "fissure/eval/bench_kinematics.hpp"
#include "fissure/eval/eval_error.hpp"
#include "fissure/session/machine_info.hpp"

#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/falcon_hw/libnifalcon_reference.hpp"
#include "fissure/falcon_hw/motor_command.hpp"

namespace fissure::eval {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
namespace {

using falcon::FalconGeometry;
using falcon::FkOptions;
using falcon::FkResult;

/// Solves timed between two clock reads (see file comment).
constexpr std::size_t kBatchSize = kKinematicsBatchSize;
/// The rt loop's rate and the fastest hand speed the kinematics must follow.
constexpr double kSamplePeriod_s = 1e-3;
constexpr double kMaxHandSpeed_m_per_s = 0.5;
constexpr double kMinHandSpeed_m_per_s = 0.1;
/// Waypoints stay inside this fraction of the workspace radius.
constexpr double kWaypointRadiusFraction = 0.95;
/// Central-difference step for the Jacobian check (m); see kinematics_test.cpp.
constexpr double kFiniteDifferenceStep_m = 1e-6;

Eigen::Vector3d workspace_centre() {
  return {falcon::kWorkspaceCentre_device_m[0], falcon::kWorkspaceCentre_device_m[1],
          falcon::kWorkspaceCentre_device_m[2]};
}

struct Trajectory {
  std::vector<Eigen::Vector3d> p_device_m;
  std::vector<Eigen::Vector3d> theta_rad;
  double max_step_m = 0.0;
  double max_speed_m_per_s = 0.0;
};

Eigen::Vector3d random_in_ball(std::mt19937_64& rng, double radius_m) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  while (true) {
    const Eigen::Vector3d v{unit(rng), unit(rng), unit(rng)};
    if (v.squaredNorm() <= 1.0) return workspace_centre() + radius_m * v;
  }
}

/// Min-jerk moves between random waypoints: s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ has peak speed
/// 1.875 D/T, so T = 1.875 D / v_peak gives the chosen peak speed exactly.
Trajectory make_hand_trajectory(std::size_t samples, std::uint64_t seed) {
  const FalconGeometry geometry;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> speed(kMinHandSpeed_m_per_s, kMaxHandSpeed_m_per_s);
  Trajectory trajectory;
  trajectory.p_device_m.reserve(samples);
  Eigen::Vector3d from = workspace_centre();
  while (trajectory.p_device_m.size() < samples) {
    const Eigen::Vector3d to = random_in_ball(rng, kWaypointRadiusFraction * falcon::kWorkspaceRadius_m);
    const double distance_m = (to - from).norm();
    const double duration_s = 1.875 * distance_m / speed(rng);
    const auto ticks = static_cast<std::size_t>(std::ceil(duration_s / kSamplePeriod_s));
    for (std::size_t k = 1; k <= ticks && trajectory.p_device_m.size() < samples; ++k) {
      const double tau = std::min(1.0, static_cast<double>(k) * kSamplePeriod_s / duration_s);
      const double s = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
      trajectory.p_device_m.push_back(from + s * (to - from));
    }
    from = to;
  }
  trajectory.theta_rad.resize(samples);
  for (std::size_t k = 0; k < samples; ++k) {
    if (!falcon::inverse_kinematics(geometry, trajectory.p_device_m[k], trajectory.theta_rad[k])) {
      throw EvalError("bench kinematics: trajectory sample " + std::to_string(k) + " is not reachable (bug)");
    }
    if (k > 0) {
      trajectory.max_step_m =
          std::max(trajectory.max_step_m, (trajectory.p_device_m[k] - trajectory.p_device_m[k - 1]).norm());
    }
  }
  trajectory.max_speed_m_per_s = trajectory.max_step_m / kSamplePeriod_s;
  return trajectory;
}

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const auto index = static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(values.size()))) - 1;
  return values[std::min(index, values.size() - 1)];
}
double median(std::vector<double> values) { return percentile(std::move(values), 0.5); }

/// Calls solve(k) for every k in order, reading the clock once per kBatchSize solves;
/// appends per-solve nanoseconds (batch time / batch size) to ns_per_solve.
template <typename Solve>
void time_in_batches(std::size_t count, Solve&& solve, std::vector<double>& ns_per_solve) {
  for (std::size_t begin = 0; begin + kBatchSize <= count; begin += kBatchSize) {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t k = begin; k < begin + kBatchSize; ++k) solve(k);
    const auto stop = std::chrono::steady_clock::now();
    ns_per_solve.push_back(std::chrono::duration<double, std::nano>(stop - start).count() /
                           static_cast<double>(kBatchSize));
  }
}

struct SolveStats {
  std::string label;
  double tolerance_rad = 0.0;
  double median_ns = 0.0;
  double p99_ns = 0.0;
  double iterations_mean = 0.0;
  int iterations_max = 0;
  double error_median_m = 0.0;
  double error_max_m = 0.0;
  double converged_fraction = 0.0;
};

/// Runs `solve(k, p_out) → FkResult` over the trajectory `repeats` times (timed), then
/// scores the last run's positions against the true samples.
template <typename Solve>
SolveStats measure(const std::string& label, double tolerance_rad, const Trajectory& trajectory, int repeats,
                   Solve&& solve) {
  const std::size_t count = trajectory.p_device_m.size() / kBatchSize * kBatchSize;
  std::vector<Eigen::Vector3d> solved(count);
  std::vector<FkResult> results(count);
  std::vector<double> ns_per_solve;
  for (int repeat = 0; repeat <= repeats; ++repeat) {  // repeat 0 warms caches and branch predictors
    std::vector<double> timings;
    time_in_batches(count, [&](std::size_t k) { results[k] = solve(k, solved); }, timings);
    if (repeat > 0) ns_per_solve.insert(ns_per_solve.end(), timings.begin(), timings.end());
  }
  SolveStats stats;
  stats.label = label;
  stats.tolerance_rad = tolerance_rad;
  stats.median_ns = median(ns_per_solve);
  stats.p99_ns = percentile(ns_per_solve, 0.99);
  std::vector<double> errors(count);
  double iterations_sum = 0.0;
  std::size_t converged = 0;
  for (std::size_t k = 0; k < count; ++k) {
    errors[k] = (solved[k] - trajectory.p_device_m[k]).norm();
    if (!std::isfinite(errors[k])) errors[k] = std::numeric_limits<double>::infinity();
    iterations_sum += results[k].iterations;
    stats.iterations_max = std::max(stats.iterations_max, results[k].iterations);
    if (results[k].converged) ++converged;
  }
  stats.iterations_mean = iterations_sum / static_cast<double>(count);
  stats.error_median_m = median(errors);
  stats.error_max_m = *std::max_element(errors.begin(), errors.end());
  stats.converged_fraction = static_cast<double>(converged) / static_cast<double>(count);
  return stats;
}

SolveStats measure_fk(bool warm, double tolerance_rad, const Trajectory& trajectory, int repeats) {
  const FalconGeometry geometry;
  const FkOptions options{tolerance_rad, falcon::kDefaultFkMaxIterations};
  if (warm) {
    // Sample 0 starts from the workspace centre (the loop's first tick); every later solve
    // starts from the previous solve's answer.
    return measure("warm", tolerance_rad, trajectory, repeats, [&](std::size_t k, std::vector<Eigen::Vector3d>& out) {
      out[k] = k == 0 ? workspace_centre() : out[k - 1];
      return falcon::forward_kinematics(geometry, trajectory.theta_rad[k], out[k], options);
    });
  }
  return measure("cold", tolerance_rad, trajectory, repeats, [&](std::size_t k, std::vector<Eigen::Vector3d>& out) {
    return falcon::forward_kinematics_cold(geometry, trajectory.theta_rad[k], out[k], options);
  });
}

SolveStats measure_baseline(const std::string& label, bool warm, falcon::libnifalcon_reference::JacobianVariant variant,
                            const Trajectory& trajectory, int repeats) {
  const FalconGeometry geometry;
  namespace ref = falcon::libnifalcon_reference;
  const Eigen::Vector3d first_guess{ref::kFirstGuess_device_m[0], ref::kFirstGuess_device_m[1],
                                    ref::kFirstGuess_device_m[2]};
  return measure(label, ref::kTargetError_rad, trajectory, repeats,
                 [&](std::size_t k, std::vector<Eigen::Vector3d>& out) {
                   out[k] = (warm && k > 0) ? out[k - 1] : first_guess;
                   return ref::forward_kinematics(geometry, trajectory.theta_rad[k], out[k], variant);
                 });
}

/// Times a function of the sample index alone (IK, Jacobian, motor command).
template <typename Call>
std::pair<double, double> time_call(std::size_t count, int repeats, Call&& call) {
  std::vector<double> ns_per_call;
  for (int repeat = 0; repeat <= repeats; ++repeat) {
    std::vector<double> timings;
    time_in_batches(count, call, timings);
    if (repeat > 0) ns_per_call.insert(ns_per_call.end(), timings.begin(), timings.end());
  }
  return {median(ns_per_call), percentile(ns_per_call, 0.99)};
}

/// Worst row-wise relative error of the analytic ∂θ/∂p against central differences of IK.
double jacobian_max_relative_error(const std::vector<Eigen::Vector3d>& points) {
  const FalconGeometry geometry;
  double worst = 0.0;
  for (const Eigen::Vector3d& p : points) {
    Eigen::Vector3d theta;
    Eigen::Matrix3d analytic;
    if (!falcon::inverse_kinematics_with_derivative(geometry, p, theta, analytic)) {
      throw EvalError("bench kinematics: workspace point is not reachable (bug)");
    }
    Eigen::Matrix3d numeric;
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3d plus = p;
      Eigen::Vector3d minus = p;
      plus[axis] += kFiniteDifferenceStep_m;
      minus[axis] -= kFiniteDifferenceStep_m;
      Eigen::Vector3d theta_plus;
      Eigen::Vector3d theta_minus;
      if (!falcon::inverse_kinematics(geometry, plus, theta_plus) ||
          !falcon::inverse_kinematics(geometry, minus, theta_minus)) {
        throw EvalError("bench kinematics: finite-difference point is not reachable (bug)");
      }
      numeric.col(axis) = (theta_plus - theta_minus) / (2.0 * kFiniteDifferenceStep_m);
    }
    for (int row = 0; row < 3; ++row) {
      worst = std::max(worst, (analytic.row(row) - numeric.row(row)).norm() / numeric.row(row).norm());
    }
  }
  return worst;
}

nlohmann::json to_json(const SolveStats& s) {
  return {{"start", s.label},
          {"tolerance_rad", s.tolerance_rad},
          {"median_ns", s.median_ns},
          {"p99_ns", s.p99_ns},
          {"iterations_mean", s.iterations_mean},
          {"iterations_max", s.iterations_max},
          {"error_median_m", s.error_median_m},
          {"error_max_m", s.error_max_m},
          {"converged_fraction", s.converged_fraction}};
}

void print_row(const SolveStats& s) {
  std::printf("%-44s %8.0e %7.2f %4d %9.0f %9.0f %12.3e %12.3e %7.4f\n", s.label.c_str(), s.tolerance_rad,
              s.iterations_mean, s.iterations_max, s.median_ns, s.p99_ns, s.error_median_m, s.error_max_m,
              s.converged_fraction);
}


/// FK(IK(p)) from a cold start and the Jacobian against central differences, over uniform points
/// of the workspace ball.
struct UniformPointsCheck {
  double cold_max_error_m = 0.0;
  double jacobian_max_relative_error = 0.0;
};

UniformPointsCheck check_uniform_points(const FalconGeometry& geometry, std::uint64_t seed, std::size_t points) {
  std::vector<Eigen::Vector3d> uniform;
  {
    std::mt19937_64 rng(seed + 1);
    for (std::size_t k = 0; k < points; ++k) uniform.push_back(random_in_ball(rng, falcon::kWorkspaceRadius_m));
  }
  double uniform_cold_max_error_m = 0.0;
  for (const Eigen::Vector3d& p : uniform) {
    Eigen::Vector3d theta;
    Eigen::Vector3d solved;
    if (!falcon::inverse_kinematics(geometry, p, theta)) throw EvalError("bench kinematics: IK failed in workspace (bug)");
    const FkResult result = falcon::forward_kinematics_cold(geometry, theta, solved, FkOptions{});
    uniform_cold_max_error_m =
        std::max(uniform_cold_max_error_m, result.converged ? (solved - p).norm() : std::numeric_limits<double>::infinity());
  }
  return {uniform_cold_max_error_m, jacobian_max_relative_error(uniform)};
}

/// Warm and cold FK for tolerances 1e-3 … 1e-12 rad, each row printed as it is measured.
std::vector<SolveStats> tolerance_table(const Trajectory& trajectory, int repeats) {
  std::vector<SolveStats> table;
  for (const bool warm : {true, false}) {
    for (int exponent = -3; exponent >= -12; --exponent) {
      table.push_back(measure_fk(warm, std::pow(10.0, exponent), trajectory, repeats));
      print_row(table.back());
    }
  }
  return table;
}

nlohmann::json run_kinematics(const BenchKinematicsOptions& args) {
  if (args.samples < 2 * kBatchSize) throw EvalError("bench kinematics: --samples: need at least 128 samples", true);
  const FalconGeometry geometry;
  const Trajectory trajectory = make_hand_trajectory(args.samples, args.seed);
  const std::size_t count = trajectory.p_device_m.size() / kBatchSize * kBatchSize;

  constexpr std::size_t kUniformPoints = 10000;
  const UniformPointsCheck uniform = check_uniform_points(geometry, args.seed, kUniformPoints);
  const double uniform_cold_max_error_m = uniform.cold_max_error_m;
  const double jacobian_error = uniform.jacobian_max_relative_error;

  std::printf("fissure bench kinematics: %zu hand samples at 1 kHz (max step %.3f mm, max speed %.3f m/s), "
              "%d timed repeats, %zu solves per clock read\n",
              count, trajectory.max_step_m * 1e3, trajectory.max_speed_m_per_s, args.repeats, kBatchSize);
  std::printf("%-44s %8s %7s %4s %9s %9s %12s %12s %7s\n", "start", "tol_rad", "it_mean", "max", "med_ns", "p99_ns",
              "err_med_m", "err_max_m", "conv");
  const std::vector<SolveStats> table = tolerance_table(trajectory, args.repeats);
  const SolveStats warm_default = measure_fk(true, falcon::kDefaultFkTolerance_rad, trajectory, args.repeats);
  const SolveStats cold_default = measure_fk(false, falcon::kDefaultFkTolerance_rad, trajectory, args.repeats);
  // What the rt loop needs per tick: the position and J at it, in one call.
  std::vector<Eigen::Matrix3d> fk_jacobians(count);
  const SolveStats warm_with_jacobian = measure(
      "warm + J (forward_kinematics_with_jacobian)", falcon::kDefaultFkTolerance_rad, trajectory, args.repeats,
      [&](std::size_t k, std::vector<Eigen::Vector3d>& out) {
        out[k] = k == 0 ? workspace_centre() : out[k - 1];
        bool valid = false;
        return falcon::forward_kinematics_with_jacobian(geometry, trajectory.theta_rad[k], out[k],
                                                        FkOptions{falcon::kDefaultFkTolerance_rad,
                                                                  falcon::kDefaultFkMaxIterations},
                                                        fk_jacobians[k], valid);
      });

  namespace ref = falcon::libnifalcon_reference;
  const SolveStats baseline = measure_baseline("libnifalcon: guess (0,0,0.08), issue-66 J", false,
                                               ref::JacobianVariant::kIssue66, trajectory, args.repeats);
  const SolveStats baseline_corrected = measure_baseline("libnifalcon: guess (0,0,0.08), corrected J", false,
                                                         ref::JacobianVariant::kCorrected, trajectory, args.repeats);
  const SolveStats baseline_warm = measure_baseline("libnifalcon: previous solution, issue-66 J", true,
                                                    ref::JacobianVariant::kIssue66, trajectory, args.repeats);
  std::printf("baselines (libnifalcon's scheme: gain 0.5 halved on divergence, stop at 0.01 rad or 15 tries):\n");
  print_row(baseline);
  print_row(baseline_corrected);
  print_row(baseline_warm);
  std::printf("default tolerance %.0e rad:\n", falcon::kDefaultFkTolerance_rad);
  print_row(warm_default);
  print_row(cold_default);
  print_row(warm_with_jacobian);

  const auto [ik_median_ns, ik_p99_ns] = time_call(count, args.repeats, [&, out = Eigen::Vector3d{}](std::size_t k) mutable {
    (void)falcon::inverse_kinematics(geometry, trajectory.p_device_m[k], out);
  });
  std::vector<Eigen::Matrix3d> jacobians(count);
  const auto [jacobian_median_ns, jacobian_p99_ns] = time_call(count, args.repeats, [&](std::size_t k) {
    (void)falcon::jacobian(geometry, trajectory.p_device_m[k], jacobians[k]);
  });
  std::vector<falcon::MotorCommandResult> commands(count);
  const auto [command_median_ns, command_p99_ns] = time_call(count, args.repeats, [&](std::size_t k) {
    const Eigen::Vector3d force_n{std::sin(0.01 * static_cast<double>(k)), 2.0, -3.0};
    commands[k] = falcon::force_to_motor_counts(jacobians[k], force_n, falcon::kDefaultNewtonMetrePerCount);
  });
  std::printf("IK %.0f ns (p99 %.0f), Jacobian %.0f ns (p99 %.0f), force_to_motor_counts %.0f ns (p99 %.0f)\n",
              ik_median_ns, ik_p99_ns, jacobian_median_ns, jacobian_p99_ns, command_median_ns, command_p99_ns);

  const double roundtrip_max_error_m =
      std::max({uniform_cold_max_error_m, warm_default.error_max_m, cold_default.error_max_m});
  std::printf("FK(IK(p)) round trip at the default tolerance: max %.3e m (%zu uniform points cold, %zu trajectory "
              "points warm and cold); Jacobian vs central differences: max relative error %.3e\n",
              roundtrip_max_error_m, kUniformPoints, count, jacobian_error);

  const bool warm_error_ok = warm_default.error_max_m <= 1e-6;
  const bool warm_time_ok = warm_default.median_ns <= 500.0;
  const bool faster_than_baseline = warm_default.median_ns < baseline.median_ns;
  const bool more_accurate_than_baseline = warm_default.error_max_m < baseline.error_max_m;
  std::printf("targets: warm FK ≤ 1 µm: %s (max %.3e m); warm FK median ≤ 500 ns: %s (%.0f ns); faster than "
              "baseline: %s (%.0f vs %.0f ns); more accurate than baseline: %s (%.3e vs %.3e m)\n",
              warm_error_ok ? "MET" : "MISSED", warm_default.error_max_m, warm_time_ok ? "MET" : "MISSED",
              warm_default.median_ns, faster_than_baseline ? "MET" : "MISSED", warm_default.median_ns, baseline.median_ns,
              more_accurate_than_baseline ? "MET" : "MISSED", warm_default.error_max_m, baseline.error_max_m);

  nlohmann::json out;
  out["benchmark"] = "kinematics";
  out["machine"] = machine_info();
  out["method"] = {
      {"timing", "std::chrono::steady_clock read once per batch of " + std::to_string(kBatchSize) +
                     " consecutive solves; per-solve time = batch time / batch size; median and p99 over all batches "
                     "of all timed repeats (one untimed warm-up pass first). p99 is of 64-solve averages, not of "
                     "single solves; iterations_max bounds the single-solve worst case."},
      {"points", "hand trajectory sampled at 1 kHz: min-jerk moves between random waypoints within 0.95 of the "
                 "workspace radius, peak speeds 0.1-0.5 m/s"},
      {"warm_start", "each solve starts from the previous sample's solution (sample 0 from the workspace centre)"},
      {"cold_start", "each solve starts from the workspace centre"},
      {"error", "Euclidean distance between the FK result and the trajectory sample whose IK gave theta"},
      {"samples", count},
      {"max_step_m", trajectory.max_step_m},
      {"max_speed_m_per_s", trajectory.max_speed_m_per_s},
      {"repeats", args.repeats},
      {"seed", args.seed}};
  out["default_tolerance_rad"] = falcon::kDefaultFkTolerance_rad;
  out["fk_roundtrip_max_error_m"] = roundtrip_max_error_m;
  out["fk_roundtrip_uniform_points"] = kUniformPoints;
  out["jacobian_max_rel_error"] = jacobian_error;
  out["fk_warm_median_ns"] = warm_default.median_ns;
  out["fk_warm_p99_ns"] = warm_default.p99_ns;
  out["fk_warm_max_error_m"] = warm_default.error_max_m;
  out["fk_warm_iterations_max"] = warm_default.iterations_max;
  out["fk_warm_with_jacobian_median_ns"] = warm_with_jacobian.median_ns;
  out["fk_warm_with_jacobian_p99_ns"] = warm_with_jacobian.p99_ns;
  out["fk_cold_median_ns"] = cold_default.median_ns;
  out["fk_cold_p99_ns"] = cold_default.p99_ns;
  out["fk_cold_max_error_m"] = cold_default.error_max_m;
  out["fk_cold_iterations_max"] = cold_default.iterations_max;
  out["ik_median_ns"] = ik_median_ns;
  out["ik_p99_ns"] = ik_p99_ns;
  out["jacobian_median_ns"] = jacobian_median_ns;
  out["jacobian_p99_ns"] = jacobian_p99_ns;
  out["force_to_motor_counts_median_ns"] = command_median_ns;
  nlohmann::json baseline_json = to_json(baseline);
  baseline_json["max_error_m"] = baseline.error_max_m;
  baseline_json["jacobian"] = "libnifalcon issue-66 (sin^2 theta2 z entry), as published";
  baseline_json["first_guess_m"] = ref::kFirstGuess_device_m;
  out["baseline_libnifalcon"] = baseline_json;
  out["baseline_variants"] = {to_json(baseline_corrected), to_json(baseline_warm)};
  out["baseline_variants"][0]["jacobian"] = "corrected (ours)";
  out["baseline_variants"][1]["jacobian"] = "libnifalcon issue-66";
  out["tolerance_table"] = nlohmann::json::array();
  for (const SolveStats& row : table) out["tolerance_table"].push_back(to_json(row));
  out["targets"] = {{"warm_fk_max_error_le_1um", warm_error_ok},
                    {"warm_fk_median_le_500ns", warm_time_ok},
                    {"warm_fk_faster_than_baseline", faster_than_baseline},
                    {"warm_fk_more_accurate_than_baseline", more_accurate_than_baseline}};

  return out;
}

}  // namespace

nlohmann::json run_bench_kinematics(const BenchKinematicsOptions& options) { return run_kinematics(options); }

}  // namespace fissure::eval
