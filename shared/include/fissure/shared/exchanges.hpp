#pragma once
// The two latest-value channels between the halves of a session, named once for everyone who
// holds one end: rt_core, the host pipeline step, a link bridge, a benchmark. In one process
// they are the in-process transport; in a split deployment a link bridge pumps each to a wire.
#include "fissure/shared/latest_value_exchange.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure {

/// Host → rt_core: the newest contact proxy.
using ProxyExchange = LatestValueExchange<ContactProxy>;
/// rt_core → host: the newest device sample, mapped to the tool.
using DeviceStateExchange = LatestValueExchange<DeviceState>;

}  // namespace fissure
