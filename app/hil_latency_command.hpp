#pragma once
namespace fissure::app {
struct CommandTree;
/// `fissure hil latency [--device usb|sim] [--transport …] [--seconds N] --json FILE`.
void register_hil_latency(CommandTree& tree);
}  // namespace fissure::app
