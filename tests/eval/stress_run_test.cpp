// eval/src/stress_run.cpp: choosing cases by name and the report JSON of a run.
#include "fissure/eval/stress_run.hpp"

#include <gtest/gtest.h>

#include "fissure/eval/eval_error.hpp"

namespace fissure::eval {
namespace {

TEST(StressRun, CasesNamedKeepsTheGivenOrder) {
  const std::vector<StressCase> all = stress_cases();
  ASSERT_GE(all.size(), 2u);
  const std::vector<StressCase> chosen = stress_cases_named({all[1].name, all[0].name});
  ASSERT_EQ(chosen.size(), 2u);
  EXPECT_EQ(chosen[0].name, all[1].name);
  EXPECT_EQ(chosen[1].name, all[0].name);
}

TEST(StressRun, UnknownCaseIsABadArgumentNamingIt) {
  try {
    (void)stress_cases_named({"no_such_case"});
    FAIL() << "an unknown case name was accepted";
  } catch (const EvalError& e) {
    EXPECT_TRUE(e.bad_argument());
    EXPECT_NE(std::string(e.what()).find("no_such_case"), std::string::npos) << e.what();
  }
}

TEST(StressRun, ReportCarriesTheCountsAndEveryRow) {
  StressRunResult result;
  result.rows.resize(2);
  result.rows[0].name = "a";
  result.rows[1].name = "b";
  result.failed = 1;
  result.known_failures = 1;
  result.jobs = 2;
  StressRunOptions options;
  options.seed = 11;
  const nlohmann::json report = stress_report_json(result, options, "ci");
  EXPECT_EQ(report["profile"], "ci");
  EXPECT_EQ(report["base_seed"], 11u);
  EXPECT_EQ(report["jobs"], 2u);
  EXPECT_EQ(report["failed"], 1);
  EXPECT_EQ(report["known_failures"], 1);
  EXPECT_DOUBLE_EQ(report["energy_bound_j"].get<double>(), kStressEnergyBound_j);
  ASSERT_EQ(report["cases"].size(), 2u);
  EXPECT_EQ(report["cases"][1]["name"], "b");
  EXPECT_TRUE(report["machine"].contains("nproc"));
}

}  // namespace
}  // namespace fissure::eval
