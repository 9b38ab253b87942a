// The frame writer thread (see frame_writer.hpp).
#include "fissure/viewer/frame_writer.hpp"

#include <chrono>
#include <cstdio>
#include <exception>

#include "fissure/viewer/offscreen_context.hpp"
#include "fissure/viewer/scene_renderer.hpp"

namespace fissure::viewer {
namespace {

// How long the writer sleeps when nothing new was published: the host never signals it (that
// would put a syscall in the host step), so it polls; 1 ms is far below a frame's render time.
constexpr std::chrono::microseconds kIdlePoll{1000};

}  // namespace

FrameWriter::FrameWriter(const RenderModel& model, const FrameWriterOptions& options)
    : model_(model), options_(options), exchange_(std::make_unique<SnapshotExchange>()) {}

std::unique_ptr<FrameWriter> FrameWriter::start(const RenderModel& model, const FrameWriterOptions& options, std::string& error) {
  std::error_code ec;
  std::filesystem::create_directories(options.directory, ec);
  if (ec) {
    error = "cannot create the frames directory '" + options.directory.string() + "': " + ec.message();
    return nullptr;
  }
  std::unique_ptr<FrameWriter> writer(new FrameWriter(model, options));
  std::atomic<int> ready{0};  // 0 starting, 1 running, −1 failed
  std::string start_error;
  writer->thread_ = std::thread([w = writer.get(), &ready, &start_error] { w->run(ready, start_error); });
  ready.wait(0, std::memory_order_acquire);
  if (ready.load(std::memory_order_acquire) < 0) {
    writer->thread_.join();
    error = start_error;
    return nullptr;
  }
  return writer;
}

FrameWriter::~FrameWriter() { finish(); }

void FrameWriter::finish() noexcept {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

void FrameWriter::wait_until_written(std::uint64_t sequence) const noexcept {
  for (std::uint64_t seen = written_sequence_.load(std::memory_order_acquire); seen < sequence;) {
    written_sequence_.wait(seen, std::memory_order_acquire);
    seen = written_sequence_.load(std::memory_order_acquire);
  }
}

std::vector<double> FrameWriter::frame_times_s() const { return thread_.joinable() ? std::vector<double>{} : frame_times_s_; }
std::string FrameWriter::error() const { return failed_.load(std::memory_order_acquire) ? error_ : std::string(); }

std::filesystem::path FrameWriter::frame_path(std::uint64_t index) const {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(index));
  return options_.directory / name;
}

void FrameWriter::run(std::atomic<int>& ready, std::string& error) noexcept {
  std::unique_ptr<OffscreenContext> context;
  std::unique_ptr<SceneRenderer> renderer;
  try {
    context = OffscreenContext::create(options_.width_px, options_.height_px, error);
    if (context) renderer = std::make_unique<SceneRenderer>(model_);
  } catch (const std::exception& e) {
    error = e.what();
    context.reset();
  }
  if (!context || !renderer) {
    ready.store(-1, std::memory_order_release);
    ready.notify_all();
    return;
  }
  gl_description_ = context->description();
  ready.store(1, std::memory_order_release);
  ready.notify_all();

  auto snapshot = std::make_unique<RenderSnapshot>();
  RgbaImage image;
  std::uint64_t last_sequence = 0;
  bool failed = false;
  for (;;) {
    const bool stopping = stop_.load(std::memory_order_acquire);
    if (!exchange_->try_fetch(*snapshot)) {
      if (stopping) break;
      std::this_thread::sleep_for(kIdlePoll);
      continue;
    }
    if (last_sequence != 0 && snapshot->sequence > last_sequence + 1) {
      frames_dropped_.fetch_add(snapshot->sequence - last_sequence - 1, std::memory_order_acq_rel);
    }
    last_sequence = snapshot->sequence;
    if (!failed) {
      const auto t0 = std::chrono::steady_clock::now();
      try {
        context->begin_frame();
        renderer->draw(*snapshot, options_.camera, options_.width_px, options_.height_px, "");
        context->read_frame(image);
        write_png(image, frame_path(frames_written_.load(std::memory_order_relaxed)).string());
        frame_times_s_.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        frames_written_.fetch_add(1, std::memory_order_acq_rel);
      } catch (const std::exception& e) {
        error_ = e.what();
        failed = true;
        failed_.store(true, std::memory_order_release);
      }
    }
    written_sequence_.store(snapshot->sequence, std::memory_order_release);
    written_sequence_.notify_all();
  }
  renderer.reset();
  context.reset();
}

}  // namespace fissure::viewer
