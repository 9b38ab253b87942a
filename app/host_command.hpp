#pragma once
namespace fissure::app {
struct CommandTree;
/// `fissure host SCENE --transport can:IFACE|udp:HOST:PORT`: the host PC of a split deployment.
void register_host_command(CommandTree& tree);
}  // namespace fissure::app
