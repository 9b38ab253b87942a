// What a `fissure run` session leaves on disk (session/session_runner.hpp), in lockstep: a run
// refused before it starts leaves an earlier run's files exactly as they were; a run stopped by
// Ctrl-C still writes complete outputs; nonsense that would only show up late (a host period no
// whole number of rt periods, a ball that falls through the ground while settling, non-finite
// figures) is refused with the user's terms and nothing written.
#include "fissure/session/session_runner.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <vector>

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <variant>

#include <nlohmann/json.hpp>

#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/session/session_error.hpp"

#include "read_file.hpp"

namespace fissure::session {
namespace {
namespace fs = std::filesystem;

using test::read_file;

class SessionRunnerTest : public testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() / ("fissure-runner-" + std::to_string(::getpid()) + "-" +
                                        testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out_);
    fs::create_directories(out_);
    options_.scene = host::load_scene(host::resolve_scene_path("spatula-sphere"));
    options_.lockstep = true;
    options_.settle_s = 0.05;
    options_.duration_s = 0.05;
    options_.out_dir = out_;
    options_.plot = false;
    options_.status_line = false;
  }
  void TearDown() override { fs::remove_all(out_); }

  /// An earlier run's complete outputs, to check a refused run leaves them alone.
  void write_earlier_outputs() {
    std::ofstream(out_ / "trace.csv") << "time_s,tick\n0,0\n";
    std::ofstream(out_ / "summary.json") << "{\"earlier\": true}\n";
  }
  void expect_earlier_outputs_untouched() {
    EXPECT_EQ(read_file(out_ / "trace.csv"), "time_s,tick\n0,0\n");
    EXPECT_EQ(read_file(out_ / "summary.json"), "{\"earlier\": true}\n");
    int entries = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(out_)) ++entries;
    EXPECT_EQ(entries, 2) << "a refused run left a file behind";
  }
  std::string refusal() {
    try {
      (void)run_session(options_);
    } catch (const SessionError& e) {
      return e.what();
    }
    ADD_FAILURE() << "the session was not refused";
    return {};
  }

  fs::path out_;
  SessionOptions options_;
};

TEST_F(SessionRunnerTest, ALockstepRateThatIsNoWholeDivisorIsRefusedBeforeTouchingEarlierOutputs) {
  write_earlier_outputs();
  options_.rt_rate_hz = 700.0;
  const std::string error = refusal();
  EXPECT_NE(error.find("--rate"), std::string::npos) << error;
  EXPECT_NE(error.find("1000"), std::string::npos) << "no rate that works is suggested: " << error;
  expect_earlier_outputs_untouched();
}

TEST_F(SessionRunnerTest, AHostStepShorterThanOneRtPeriodIsRefusedAtOnceNamingTheFlagThatHelps) {
  write_earlier_outputs();
  options_.scene.simulation.time_step_s = 1e-6;
  options_.settle_s = 1.0;  // 10^6 steps of settling: the refusal must come before them
  const std::string error = refusal();
  EXPECT_NE(error.find("--host-rate"), std::string::npos) << error;
  expect_earlier_outputs_untouched();
}

TEST_F(SessionRunnerTest, USBInLockstepIsRefusedBeforeTouchingEarlierOutputs) {
  write_earlier_outputs();
  options_.device = SessionDevice::kUsb;
  EXPECT_NE(refusal().find("--lockstep"), std::string::npos);
  expect_earlier_outputs_untouched();
}

TEST_F(SessionRunnerTest, ABallThatFallsThroughTheGroundWhileSettlingIsRefusedNamingTimeStep) {
  write_earlier_outputs();
  options_.scene.simulation.time_step_s = 0.1;
  options_.settle_s = 1.0;
  const std::string error = refusal();
  EXPECT_NE(error.find("time_step_s"), std::string::npos) << error;
  EXPECT_NE(error.find("ground"), std::string::npos) << error;
  expect_earlier_outputs_untouched();
}

TEST_F(SessionRunnerTest, NonFiniteFiguresFailTheRunNamingTheQuantityAndWriteNothing) {
  write_earlier_outputs();
  std::get<host::SoftSphere>(options_.scene.soft_bodies.front().shape).radius_m = 1e6;
  const std::string error = refusal();
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
  // The quantity and when: the nodes while settling, or a trace quantity at its tick.
  EXPECT_TRUE(error.find("node positions became non-finite while settling") != std::string::npos ||
              error.find("(tick ") != std::string::npos)
      << "the quantity is not named: " << error;
  expect_earlier_outputs_untouched();
}

TEST_F(SessionRunnerTest, AnInterruptedSessionStillWritesCompleteOutputs) {
  write_earlier_outputs();
  std::atomic<bool> interrupt{true};  // Ctrl-C before the first tick: the ramp-out is the session
  options_.interrupt = &interrupt;
  options_.duration_s = 0.0;
  const SessionOutcome outcome = run_session(options_);
  EXPECT_EQ(outcome.trace_path, out_ / "trace.csv");
  EXPECT_EQ(outcome.summary_path, out_ / "summary.json");
  const std::string trace = read_file(out_ / "trace.csv");
  ASSERT_FALSE(trace.empty());
  EXPECT_EQ(trace.back(), '\n');
  std::istringstream lines(trace);
  std::string header, row;
  std::getline(lines, header);
  const auto fields = [](const std::string& s) { return std::count(s.begin(), s.end(), ',') + 1; };
  int rows = 0;
  while (std::getline(lines, row)) {
    ++rows;
    EXPECT_EQ(fields(row), fields(header)) << "row " << rows << ": " << row;
  }
  EXPECT_GT(rows, 0);
  const nlohmann::json summary = nlohmann::json::parse(read_file(out_ / "summary.json"));
  EXPECT_EQ(summary["telemetry_samples"].get<int>(), rows);
  for (const auto& entry : fs::directory_iterator(out_)) {
    EXPECT_NE(entry.path().filename().string().front(), '.') << "temporary left behind: " << entry.path();
  }
}

/// Every value of a trace column (by its header name).
std::vector<double> column(const std::string& trace, const std::string& name) {
  std::istringstream lines(trace);
  std::string header, row;
  std::getline(lines, header);
  int index = -1, at = 0;
  std::istringstream names(header);
  for (std::string field; std::getline(names, field, ','); ++at) {
    if (field == name) index = at;
  }
  EXPECT_GE(index, 0) << name;
  std::vector<double> values;
  if (index < 0) return values;
  while (std::getline(lines, row)) {
    std::istringstream cells(row);
    std::string cell;
    for (int i = 0; i <= index; ++i) std::getline(cells, cell, ',');
    values.push_back(std::stod(cell));
  }
  return values;
}

/// The largest value of a trace column (0 for an empty trace).
double column_max(const std::string& trace, const std::string& name) {
  const std::vector<double> v = column(trace, name);
  return v.empty() ? 0.0 : std::max(0.0, *std::max_element(v.begin(), v.end()));
}

/// The smallest value of a trace column (+inf for an empty trace).
double column_min(const std::string& trace, const std::string& name) {
  const std::vector<double> v = column(trace, name);
  return v.empty() ? std::numeric_limits<double>::infinity() : *std::min_element(v.begin(), v.end());
}

TEST_F(SessionRunnerTest, ARecordedLockstepSessionReplaysBitForBit) {
  // Long enough for the hand to press the spatula into the ball: the replay must reproduce a
  // contact, not just a free grip.
  options_.duration_s = 1.2;
  options_.settle_s = 0.2;
  options_.record_path = out_ / "session.frec";
  options_.out_dir = out_ / "recorded";
  const SessionOutcome recorded = run_session(options_);
  ASSERT_TRUE(fs::exists(out_ / "session.frec"));
  EXPECT_EQ(recorded.summary["recording"]["lost"].get<int>(), 0);
  const std::string recorded_trace = read_file(out_ / "recorded" / "trace.csv");
  EXPECT_GT(column_max(recorded_trace, "contact_force_n"), 0.5) << "no contact to reproduce";

  SessionOptions replay = options_;
  replay.record_path.clear();
  replay.replay_path = out_ / "session.frec";
  replay.duration_s = 0.0;  // the recorded session's length
  replay.out_dir = out_ / "replayed";
  const SessionOutcome replayed = run_session(replay);
  EXPECT_EQ(replayed.summary["device"], "replay");
  EXPECT_EQ(replayed.summary["replay"]["recorded_device"], "sim-falcon");
  EXPECT_EQ(replayed.summary["replay"]["commands_differing"].get<int>(), 0);
  EXPECT_EQ(replayed.summary["replay"]["exchanges_after_end"].get<int>(), 0);
  EXPECT_EQ(replayed.summary["ticks"], recorded.summary["ticks"]);
  EXPECT_TRUE(read_file(out_ / "replayed" / "trace.csv") == recorded_trace) << "the replayed trace differs from the recorded one";
  // The summary explains the trace's flag bits (fault_bits 16..20) by name, apart from faults.
  for (const char* flag : {"force clamped", "force rate limited", "motor saturated", "passivity controller active", "soft wall"}) {
    EXPECT_TRUE(recorded.summary["flag_ticks"].contains(flag)) << flag;
  }

  // And the replay is itself deterministic: a second replay, re-recorded, gives the same again.
  replay.out_dir = out_ / "replayed-again";
  replay.record_path = out_ / "again.frec";
  (void)run_session(replay);
  EXPECT_TRUE(read_file(out_ / "replayed-again" / "trace.csv") == recorded_trace);
}

TEST_F(SessionRunnerTest, AReplayRunsAtAnotherRateHostRateAndMethod) {
  options_.duration_s = 0.3;
  options_.record_path = out_ / "session.frec";
  options_.out_dir = out_ / "recorded";
  (void)run_session(options_);
  SessionOptions replay = options_;
  replay.record_path.clear();
  replay.replay_path = out_ / "session.frec";
  replay.duration_s = 0.0;
  replay.rt_rate_hz = 2000.0;
  replay.host_rate_hz = 500.0;
  replay.scene.simulation.collision_method = host::SceneCollisionMethod::kRay;
  replay.out_dir = out_ / "replayed";
  const SessionOutcome outcome = run_session(replay);
  const nlohmann::json& r = outcome.summary["replay"];
  EXPECT_EQ(outcome.summary["rt_rate_hz"].get<double>(), 2000.0);
  EXPECT_EQ(outcome.summary["host_rate_hz"].get<double>(), 500.0);
  // Two ticks per recorded exchange: every record answered twice, none past the end.
  EXPECT_EQ(r["records_used"], r["records"]);
  EXPECT_NEAR(r["exchanges"].get<double>(), 2.0 * r["records"].get<double>(), 2.0);
  EXPECT_EQ(r["exchanges_after_end"].get<int>(), 0);
  EXPECT_EQ(outcome.summary["faults"].get<int>(), 0) << outcome.summary.dump(1);
}

TEST_F(SessionRunnerTest, AReplayThatCannotWorkIsRefusedBeforeTouchingEarlierOutputs) {
  options_.record_path = out_ / "session.frec";
  options_.out_dir = out_ / "recorded";
  (void)run_session(options_);
  const std::string good = read_file(out_ / "session.frec");
  options_.record_path.clear();
  options_.out_dir = out_;
  write_earlier_outputs();

  std::ofstream(out_ / "cut.frec", std::ios::binary) << good.substr(0, good.size() - 3);
  options_.replay_path = out_ / "cut.frec";
  std::string error = refusal();
  EXPECT_NE(error.find((out_ / "cut.frec").string()), std::string::npos) << error;
  EXPECT_NE(error.find("at byte offset"), std::string::npos) << error;
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;

  std::string wrong_version = good;
  wrong_version[8] = 9;
  std::ofstream(out_ / "v9.frec", std::ios::binary) << wrong_version;
  options_.replay_path = out_ / "v9.frec";
  error = refusal();
  EXPECT_NE(error.find("version 9"), std::string::npos) << error;

  options_.replay_path = out_ / "recorded" / "session.frec";
  fs::rename(out_ / "session.frec", options_.replay_path);
  options_.duration_s = 10.0;
  error = refusal();
  EXPECT_NE(error.find("longer than the recorded session"), std::string::npos) << error;

  options_.duration_s = 0.0;
  options_.lockstep = false;
  options_.device = SessionDevice::kUsb;
  error = refusal();
  EXPECT_NE(error.find("--replay"), std::string::npos) << error;
  fs::remove(out_ / "cut.frec");
  fs::remove(out_ / "v9.frec");
  fs::remove_all(out_ / "recorded");
  expect_earlier_outputs_untouched();
}

/// Issue 23's grasp scenes, end to end in lockstep with the scene's own hand script: the hand
/// closes the jaws on the vessel, lifts (or pulls) and lets go; both jaws carry a normal force and
/// friction while the grip lasts, nothing crosses, and every output is complete.
void expect_grasp_session(const SessionOutcome& outcome, const fs::path& out) {
  EXPECT_EQ(outcome.trace_path, out / "trace.csv");
  const std::string trace = read_file(out / "trace.csv");
  const nlohmann::json summary = nlohmann::json::parse(read_file(out / "summary.json"));
  EXPECT_EQ(summary["crossed_nodes_max"].get<int>(), 0);
  EXPECT_EQ(summary["faults"].get<int>(), 0);
  EXPECT_GT(column_max(trace, "host_jaw_a_normal_n"), 0.2);
  EXPECT_GT(column_max(trace, "host_jaw_b_normal_n"), 0.2);
  EXPECT_GT(column_max(trace, "host_jaw_a_friction_n"), 0.05) << "the grip holds by friction";
  EXPECT_GT(column_max(trace, "host_jaw_b_friction_n"), 0.05);
  EXPECT_LT(column_min(trace, "host_jaw_gap_m"), 0.03) << "the hand closed the jaws on the 30 mm vessel";
  // rt_core renders the friction at the hand (friction_cone.hpp), within the static cone of the
  // jaws' force: never more than the commanded force itself.
  EXPECT_GT(column_max(trace, "friction_n"), 0.1) << "the hand feels the drag";
  EXPECT_LE(column_max(trace, "friction_n"), column_max(trace, "contact_force_n") + 0.05);
}

TEST_F(SessionRunnerTest, TheLiftSceneGraspsLiftsAndReleasesTheVesselEndToEnd) {
  options_.scene = host::load_scene(host::resolve_scene_path("clamp-vessel-lift"));
  options_.settle_s = 0.5;
  options_.duration_s = 0.0;  // the whole hand script: close, lift, hold, lower, open
  const SessionOutcome outcome = run_session(options_);
  expect_grasp_session(outcome, out_);
}

TEST_F(SessionRunnerTest, TheRetractionSceneGripsAndPullsTheAnchoredVesselEndToEnd) {
  options_.scene = host::load_scene(host::resolve_scene_path("clamp-vessel-retract"));
  options_.settle_s = 0.5;
  options_.duration_s = 0.0;
  const SessionOutcome outcome = run_session(options_);
  expect_grasp_session(outcome, out_);
}

}  // namespace
}  // namespace fissure::session
