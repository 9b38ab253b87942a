// A run's outputs reach their final names only when complete (session/output_staging.hpp): an
// earlier run's files survive a run that fails or is abandoned, and a committed run replaces
// them whole.
#include "fissure/session/output_staging.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "read_file.hpp"

namespace fissure::session {
namespace {
namespace fs = std::filesystem;

using test::read_file;

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

class OutputStagingTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("fissure-staging-" + std::to_string(::getpid()) + "-" +
                                        testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(OutputStagingTest, AFileIsWrittenUnderAHiddenNameWithItsExtensionAndMovedByCommit) {
  write(dir_ / "trace.csv", "old complete trace\n");
  OutputStaging staging;
  const fs::path tmp = staging.file(dir_ / "trace.csv");
  EXPECT_EQ(tmp.parent_path(), dir_);
  EXPECT_EQ(tmp.filename().string().front(), '.');
  EXPECT_EQ(tmp.extension(), ".csv");
  write(tmp, "new complete trace\n");
  EXPECT_EQ(read_file(dir_ / "trace.csv"), "old complete trace\n");
  staging.commit();
  EXPECT_EQ(read_file(dir_ / "trace.csv"), "new complete trace\n");
  EXPECT_FALSE(fs::exists(tmp));
}

TEST_F(OutputStagingTest, AnAbandonedRunLeavesTheEarlierFilesAsTheyWereAndNoTemporaries) {
  write(dir_ / "trace.csv", "old\n");
  {
    OutputStaging staging;
    write(staging.file(dir_ / "trace.csv"), "half a ro");
    write(staging.file(dir_ / "summary.json"), "{");
  }
  EXPECT_EQ(read_file(dir_ / "trace.csv"), "old\n");
  EXPECT_FALSE(fs::exists(dir_ / "summary.json"));
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST_F(OutputStagingTest, FilesStagedButNeverWrittenAreSkippedByCommit) {
  write(dir_ / "session.png", "old plot");
  OutputStaging staging;
  (void)staging.file(dir_ / "session.png");  // the plotter failed: nothing written
  staging.commit();
  EXPECT_EQ(read_file(dir_ / "session.png"), "old plot");
}

TEST_F(OutputStagingTest, AStagedDirectoryReplacesTheOldFramesAndKeepsEveryOtherFile) {
  const fs::path frames = dir_ / "frames";
  fs::create_directories(frames);
  for (int i = 0; i < 5; ++i) write(frames / ("frame_00000" + std::to_string(i) + ".png"), "old");
  write(frames / "notes.txt", "mine");
  OutputStaging staging;
  const fs::path tmp = staging.directory(frames, "frame_", ".png");
  EXPECT_EQ(tmp.parent_path(), frames);
  for (int i = 0; i < 2; ++i) write(tmp / ("frame_00000" + std::to_string(i) + ".png"), "new");
  EXPECT_EQ(read_file(frames / "frame_000004.png"), "old");
  staging.commit();
  EXPECT_EQ(read_file(frames / "frame_000000.png"), "new");
  EXPECT_EQ(read_file(frames / "frame_000001.png"), "new");
  for (int i = 2; i < 5; ++i) EXPECT_FALSE(fs::exists(frames / ("frame_00000" + std::to_string(i) + ".png"))) << i;
  EXPECT_EQ(read_file(frames / "notes.txt"), "mine");
  EXPECT_FALSE(fs::exists(tmp));
}

TEST_F(OutputStagingTest, AnUncreatableDirectoryIsNamedInTheError) {
  write(dir_ / "plain-file", "x");
  OutputStaging staging;
  try {
    (void)staging.file(dir_ / "plain-file" / "trace.csv");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("plain-file"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fissure::session
