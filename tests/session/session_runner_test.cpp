// What a `fissure run` session leaves on disk (session/session_runner.hpp), in lockstep: a run
// refused before it starts leaves an earlier run's files exactly as they were; a run stopped by
// Ctrl-C still writes complete outputs; nonsense that would only show up late (a host period no
// whole number of rt periods, a ball that falls through the ground while settling, non-finite
// figures) is refused with the user's terms and nothing written.
#include "fissure/session/session_runner.hpp"

#include <gtest/gtest.h>

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
  std::get<host::SoftSphere>(options_.scene.soft_body.shape).radius_m = 1e6;
  const std::string error = refusal();
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
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

}  // namespace
}  // namespace fissure::session
