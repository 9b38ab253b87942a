// The frame writer thread: every snapshot the caller waits for becomes a readable PNG.
#include "fissure/viewer/frame_writer.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>

#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/viewer/offscreen_context.hpp"

namespace fissure::viewer {
namespace {

TEST(FrameWriter, WritesOnePngPerWaitedSnapshot) {
  host::HostSimulation sim(host::load_scene(host::resolve_scene_path("spatula-sphere")));
  sim.settle(0.01);
  const RenderModel model = make_render_model(sim);
  FrameWriterOptions options;
  options.directory = std::filesystem::temp_directory_path() / "fissure_frame_writer_test";
  std::filesystem::remove_all(options.directory);
  options.width_px = 320;
  options.height_px = 240;
  options.camera = default_camera(model);
  std::string error;
  auto writer = FrameWriter::start(model, options, error);
  ASSERT_NE(writer, nullptr) << "cannot start the frame writer: " << error;
  auto snapshot = std::make_unique<RenderSnapshot>();
  for (int i = 0; i < 3; ++i) {
    (void)sim.step(host::to_tool_pose(sim.scene().trajectory.start));
    capture_snapshot(sim, *snapshot);
    writer->publish(*snapshot);
    writer->wait_until_written(snapshot->sequence);
    EXPECT_EQ(writer->frames_written(), static_cast<std::uint64_t>(i + 1));
  }
  writer->finish();
  EXPECT_EQ(writer->frames_dropped(), 0U);
  EXPECT_EQ(writer->frame_times_s().size(), 3U);
  EXPECT_TRUE(writer->error().empty());
  for (std::uint64_t i = 0; i < 3; ++i) {
    const RgbaImage image = read_png(writer->frame_path(i).string());
    EXPECT_EQ(image.width, 320);
    EXPECT_EQ(image.height, 240);
  }
  EXPECT_FALSE(std::filesystem::exists(writer->frame_path(3)));
}

TEST(FrameWriter, UnwritableDirectoryIsAClearError) {
  RenderModel model;
  FrameWriterOptions options;
  options.directory = "/proc/fissure-cannot-write-here";
  std::string error;
  EXPECT_EQ(FrameWriter::start(model, options, error), nullptr);
  EXPECT_NE(error.find("/proc/fissure-cannot-write-here"), std::string::npos);
}

}  // namespace
}  // namespace fissure::viewer
