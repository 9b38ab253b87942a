#include "fissure/session/rt_stack.hpp"

#include <chrono>
#include <string>
#include <utility>

#include "fissure/session/session_error.hpp"

namespace fissure::session {

rt::RtModel build_rt_model(const rt::RtConfig& config) {
  rt::RtModel model;
  const char* error = nullptr;
  if (!rt::build_model(config, model, &error)) throw SessionError(std::string("rt config: ") + error);
  return model;
}

RtStack::RtStack(const rt::RtModel& model, falcon::HapticDevice& device, Clock& clock)
    : channels_(std::make_unique<RtChannels>()),
      loop_(std::make_unique<rt::RtLoop>(model, device, clock, channels_->proxy, channels_->state, channels_->telemetry)) {}

RtThread::RtThread(const rt::RtThreadConfig& config, std::function<void()> body)
    : thread_([this, config, body = std::move(body)] {
        rt::RtThreadSetup setup;
        const auto start = std::chrono::steady_clock::now();
        report_ = setup.apply(config);
        setup_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (report_.ok) body();
        done_.store(true, std::memory_order_release);
      }) {}

RtThread::~RtThread() {
  if (thread_.joinable()) thread_.join();
}

void RtThread::join() {
  if (thread_.joinable()) thread_.join();
}

}  // namespace fissure::session
