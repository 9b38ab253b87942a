// The frame writer thread (see frame_writer.hpp).
#include "fissure/viewer/frame_writer.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
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
  writer->started_ = true;
  return writer;
}

FrameWriter::~FrameWriter() { finish(); }

void FrameWriter::finish() noexcept {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (started_ && !finished_) {
    finished_ = true;
    write_index();
  }
}

void FrameWriter::write_index() noexcept {
  const std::filesystem::path path = options_.directory / "frames.json";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    if (!failed_.load(std::memory_order_acquire)) {
      error_ = "cannot write '" + path.string() + "'";
      failed_.store(true, std::memory_order_release);
    }
    return;
  }
  const OrbitCamera& c = options_.camera;
  const auto centre = c.project(model_.focus_world_m, options_.width_px, options_.height_px);
  const float radius_px = c.projected_radius_px(model_.focus_world_m, model_.focus_radius_m, options_.height_px);
  std::fprintf(f, "{\n  \"scene\": \"%s\",\n  \"width_px\": %d,\n  \"height_px\": %d,\n", model_.scene_name.c_str(), options_.width_px,
               options_.height_px);
  std::fprintf(f,
               "  \"camera\": {\"target_world_m\": [%.6g, %.6g, %.6g], \"yaw_deg\": %.6g, \"pitch_deg\": %.6g, \"distance_m\": %.6g, "
               "\"fov_y_deg\": %.6g},\n",
               c.target_world_m.x(), c.target_world_m.y(), c.target_world_m.z(), c.yaw_deg, c.pitch_deg, c.distance_m, c.fov_y_deg);
  // Where the camera puts the subject (the settled soft body's bounding sphere): its centre
  // and radius in pixels, x right and y down from the top-left.
  std::fprintf(f, "  \"subject_px\": {\"x\": %.3f, \"y\": %.3f, \"radius\": %.3f, \"radius_m\": %.6g},\n",
               centre ? centre->x() : -1.0F, centre ? centre->y() : -1.0F, radius_px, model_.focus_radius_m);
  std::fprintf(f, "  \"frames_written\": %llu,\n  \"frames_dropped\": %llu,\n  \"frames\": [",
               static_cast<unsigned long long>(frames_written_.load()), static_cast<unsigned long long>(frames_dropped()));
  for (std::size_t i = 0; i < records_.size(); ++i) {
    std::fprintf(f, "%s\n    {\"file\": \"%s\", \"sequence\": %llu, \"time_s\": %.6f}", i == 0 ? "" : ",",
                 frame_path(i).filename().c_str(), static_cast<unsigned long long>(records_[i].sequence), records_[i].time_s);
  }
  std::fprintf(f, "\n  ]\n}\n");
  if (std::fclose(f) != 0 && !failed_.load(std::memory_order_acquire)) {
    error_ = "cannot write '" + path.string() + "'";
    failed_.store(true, std::memory_order_release);
  }
}

void FrameWriter::wait_until_written(std::uint64_t sequence) const noexcept {
  for (std::uint64_t seen = written_sequence_.load(std::memory_order_acquire); seen < sequence;) {
    written_sequence_.wait(seen, std::memory_order_acquire);
    seen = written_sequence_.load(std::memory_order_acquire);
  }
}

std::vector<double> FrameWriter::frame_times_s() const { return thread_.joinable() ? std::vector<double>{} : frame_times_s_; }
std::vector<FrameRecord> FrameWriter::frame_records() const { return thread_.joinable() ? std::vector<FrameRecord>{} : records_; }
std::string FrameWriter::error() const { return failed_.load(std::memory_order_acquire) ? error_ : std::string(); }

std::filesystem::path FrameWriter::frame_path(std::uint64_t index) const {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(index));
  return options_.directory / name;
}

void FrameWriter::run(std::atomic<int>& ready, std::string& error) noexcept {
  if (options_.nice_increment > 0) {
    // Linux: nice is per thread (PRIO_PROCESS with a thread id). Lowering it needs no
    // privilege; if it fails anyway the writer just runs at normal priority.
    const auto tid = static_cast<id_t>(::gettid());
    errno = 0;
    const int current = ::getpriority(PRIO_PROCESS, tid);
    if (errno == 0) (void)::setpriority(PRIO_PROCESS, tid, current + options_.nice_increment);
  }
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
  bool failed = false;
  for (;;) {
    const bool stopping = stop_.load(std::memory_order_acquire);
    if (!exchange_->try_fetch(*snapshot)) {
      if (stopping) break;
      std::this_thread::sleep_for(kIdlePoll);
      continue;
    }
    frames_fetched_.fetch_add(1, std::memory_order_acq_rel);
    if (!failed) {
      const auto t0 = std::chrono::steady_clock::now();
      try {
        context->begin_frame();
        renderer->draw(*snapshot, options_.camera, options_.width_px, options_.height_px, "");
        context->read_frame(image);
        write_png(image, frame_path(frames_written_.load(std::memory_order_relaxed)).string());
        frame_times_s_.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        records_.push_back({snapshot->sequence, snapshot->overlay.time_s});
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
