#pragma once
namespace fissure::app {
struct CommandTree;
/// `fissure rt --transport can:IFACE|udp:HOST:PORT`: the rt box of a split deployment.
void register_rt_command(CommandTree& tree);
}  // namespace fissure::app
