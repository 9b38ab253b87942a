// `fissure device probe`            connected? firmware loaded? homed? encoders, buttons
// `fissure device firmware --file F` upload the user's firmware image (we never ship it)
// `fissure device home`             homing with LED feedback: pull the grip out, push it in
// All three talk to a real Falcon through LibusbFalconTransport + FalconUsbDriver; with no
// Falcon attached they fail with one line naming the USB id and the udev rule.
#include "device_usb.hpp"

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "fissure/falcon_hw/falcon_usb_driver.hpp"
#include "fissure/falcon_hw/firmware_image.hpp"
#include "fissure/falcon_hw/libusb_transport.hpp"
#include "fissure/shared/clock.hpp"

namespace fissure::app {
namespace {

// Packets the probe exchanges to report a settled reading (and the link's health).
constexpr int kProbeExchanges = 100;

struct UsbSession {
  std::unique_ptr<falcon::LibusbFalconTransport> transport;
  MonotonicClock clock;
  std::unique_ptr<falcon::FalconUsbDriver> driver;
};

// Opens the device and the driver (kOpened), or throws CommandError with one line.
std::unique_ptr<UsbSession> open_session(unsigned index) {
  auto session = std::make_unique<UsbSession>();
  std::string error;
  session->transport = falcon::LibusbFalconTransport::open(index, error);
  if (!session->transport) throw CommandError(error);
  session->driver = std::make_unique<falcon::FalconUsbDriver>(*session->transport, session->clock);
  if (!session->driver->open()) throw CommandError(session->driver->error());
  return session;
}

// check_firmware() distinguishes "no firmware" (false, still kOpened) from a failed link (kFault).
bool firmware_loaded(falcon::FalconUsbDriver& driver) {
  if (driver.check_firmware()) return true;
  if (driver.state() == falcon::DriverState::kFault) throw CommandError(driver.error());
  return false;
}

std::string bits(unsigned value, int count) {
  std::string text;
  for (int i = count - 1; i >= 0; --i) text += ((value >> i) & 1U) != 0 ? '1' : '0';
  return text;
}

void run_probe(unsigned index, bool as_json) {
  auto session = open_session(index);
  falcon::FalconUsbDriver& driver = *session->driver;
  nlohmann::json out;
  out["connected"] = true;
  out["device"] = driver.name();
  const bool loaded = firmware_loaded(driver);
  out["firmware_loaded"] = loaded;
  if (loaded) {
    if (!driver.start_running()) throw CommandError(driver.error());
    falcon::DeviceReading reading;
    int ok = 0;
    for (int i = 0; i < kProbeExchanges; ++i) {
      const falcon::IoStatus status = driver.try_exchange(falcon::DeviceCommand{}, reading);
      if (status == falcon::IoStatus::kDisconnected) throw CommandError(driver.error());
      ok += status == falcon::IoStatus::kOk ? 1 : 0;
    }
    if (ok == 0) throw CommandError("Novint Falcon answered the firmware check but then none of " +
                                    std::to_string(kProbeExchanges) + " packets");
    const falcon::DeviceReading& last = driver.last_reading();
    out["homed_mask"] = last.homed_mask;
    out["homed"] = last.homed_mask == falcon::kHomedMaskAllArms;
    out["encoder_counts"] = {last.encoder_counts[0], last.encoder_counts[1], last.encoder_counts[2]};
    out["buttons"] = last.buttons;
    out["replies_ok"] = ok;
    out["exchanges"] = kProbeExchanges;
    out["discarded_bytes"] = driver.parser_stats().total_discarded_bytes();
  }
  driver.close();
  if (as_json) {
    std::printf("%s\n", out.dump().c_str());
    return;
  }
  std::printf("Novint Falcon #%u: connected\n", index);
  if (!loaded) {
    std::printf("  firmware : not loaded (run 'fissure device firmware --file F' with your Falcon firmware)\n");
    return;
  }
  const auto& counts = out["encoder_counts"];
  std::printf("  firmware : loaded\n");
  std::printf("  homed    : %s (arms 3..1: %s)\n", out["homed"].get<bool>() ? "yes" : "no",
              bits(out["homed_mask"].get<unsigned>(), 3).c_str());
  std::printf("  encoders : %d %d %d\n", counts[0].get<int>(), counts[1].get<int>(), counts[2].get<int>());
  std::printf("  buttons  : %s\n", bits(out["buttons"].get<unsigned>(), 4).c_str());
  std::printf("  link     : %d of %d replies ok\n", out["replies_ok"].get<int>(), kProbeExchanges);
}

void run_firmware(unsigned index, const std::string& path) {
  std::vector<std::uint8_t> image;
  std::string error;
  if (!falcon::read_firmware_image(path, image, error)) throw CommandError(error);
  auto session = open_session(index);
  falcon::FalconUsbDriver& driver = *session->driver;
  std::printf("uploading %zu bytes of firmware from '%s' …\n", image.size(), path.c_str());
  std::fflush(stdout);
  if (!driver.upload_firmware(image)) throw CommandError(driver.error());
  driver.close();
  std::printf("firmware uploaded and running (echo verified); next: 'fissure device home'\n");
}

void run_home(unsigned index, double timeout_s) {
  auto session = std::make_unique<UsbSession>();
  std::string error;
  session->transport = falcon::LibusbFalconTransport::open(index, error);
  if (!session->transport) throw CommandError(error);
  falcon::FalconUsbConfig config;
  config.homing_timeout_ns = from_seconds(timeout_s);
  session->driver = std::make_unique<falcon::FalconUsbDriver>(*session->transport, session->clock, config);
  falcon::FalconUsbDriver& driver = *session->driver;
  if (!driver.open()) throw CommandError(driver.error());
  if (!firmware_loaded(driver)) {
    throw CommandError("Novint Falcon firmware not loaded: run 'fissure device firmware --file F' first");
  }
  std::printf("homing (LED red): pull the grip all the way out, then push it all the way in …\n");
  std::fflush(stdout);
  const bool homed = driver.home([](std::uint8_t mask) {
    std::printf("  arms homed: %s\n", bits(mask, 3).c_str());
    std::fflush(stdout);
  });
  if (!homed) throw CommandError(driver.error());
  driver.close();
  std::printf("homed (LED green)\n");
}

}  // namespace

void register_device_usb(CommandTree& tree) {
  struct Options {
    unsigned index = 0;
    bool json = false;
    std::string firmware_file;
    double homing_timeout_s = 60.0;
  };
  auto options = std::make_shared<Options>();

  auto* probe = tree.device.add_subcommand("probe", "Is a Falcon attached? Firmware loaded? Homed? Encoders, buttons");
  probe->add_option("--index", options->index, "which attached Falcon (0 = first)");
  probe->add_flag("--json", options->json, "print one JSON object instead of a table");
  probe->callback([options] { run_probe(options->index, options->json); });

  auto* firmware = tree.device.add_subcommand("firmware", "Upload the Falcon firmware from a file you supply");
  firmware->add_option("--file", options->firmware_file, "firmware image (not shipped with Fissure)")->required();
  firmware->add_option("--index", options->index, "which attached Falcon (0 = first)");
  firmware->callback([options] { run_firmware(options->index, options->firmware_file); });

  auto* home = tree.device.add_subcommand("home", "Home the Falcon: pull the grip out and push it in (LED feedback)");
  home->add_option("--index", options->index, "which attached Falcon (0 = first)");
  home->add_option("--timeout", options->homing_timeout_s, "seconds to wait for all three arms (s)")
      ->check(CLI::Range(1.0, 600.0));
  home->callback([options] { run_home(options->index, options->homing_timeout_s); });
}

}  // namespace fissure::app
