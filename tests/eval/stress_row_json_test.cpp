// eval/src/stress_row_json.cpp: a stress row survives the JSON round trip the parallel runner
// uses between a case's child process and the parent, and a missing field is named.
#include "fissure/eval/stress_row_json.hpp"

#include <gtest/gtest.h>

namespace fissure::eval {
namespace {

StressRow sample_row() {
  StressRow row;
  row.name = "hand_jerks";
  row.group = "device input";
  row.seed = 0x9E3779B97F4A7C15ull;
  row.ticks = 20000;
  row.host_steps = 2000;
  row.passed = false;
  row.known_failure = true;
  row.failures = {"energy: 0.03 J > 0.025 J", "crossed nodes: 1"};
  row.force_max_n = 7.5;
  row.force_limit_n = 8.0;
  row.energy_max_j = 0.03;
  row.crossed_nodes_max = 1;
  row.fault_bits_seen = 0x5;
  row.fault_bits_allowed = 0x1;
  row.recoveries_required = 3;
  row.recoveries_done = 2;
  row.contact_ticks = 1234;
  row.wall_s = 1.25;
  row.note = "refused: no volume";
  return row;
}

TEST(StressRowJson, RoundTripKeepsEveryField) {
  const StressRow row = sample_row();
  const nlohmann::json json = stress_row_to_json(row);
  // Through text, as the pipe from a child process carries it.
  const StressRow back = stress_row_from_json(nlohmann::json::parse(json.dump()));
  EXPECT_EQ(stress_row_to_json(back), json);
  EXPECT_EQ(back.name, row.name);
  EXPECT_EQ(back.seed, row.seed);
  EXPECT_EQ(back.failures, row.failures);
  EXPECT_EQ(back.known_failure, row.known_failure);
  EXPECT_DOUBLE_EQ(back.energy_max_j, row.energy_max_j);
}

TEST(StressRowJson, MissingFieldIsNamed) {
  nlohmann::json json = stress_row_to_json(sample_row());
  json.erase("energy_max_j");
  try {
    (void)stress_row_from_json(json);
    FAIL() << "a row without energy_max_j was accepted";
  } catch (const nlohmann::json::exception& e) {
    EXPECT_NE(std::string(e.what()).find("energy_max_j"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fissure::eval
