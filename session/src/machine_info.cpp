#include "fissure/session/machine_info.hpp"

#include <sys/utsname.h>

#include <fstream>
#include <string>
#include <thread>

namespace fissure::session {

nlohmann::json machine_info() {
  nlohmann::json machine;
  machine["nproc"] = std::thread::hardware_concurrency();
  std::string cpu_model = "unknown";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    // x86 says "model name", aarch64 kernels say "Model" (or nothing at all).
    if (line.rfind("model name", 0) == 0 || line.rfind("Model", 0) == 0) {
      cpu_model = line.substr(line.find(':') + 2);
      break;
    }
  }
  machine["cpu_model"] = cpu_model;
  utsname names{};
  if (uname(&names) == 0) {
    machine["kernel"] = std::string(names.sysname) + " " + names.release + " " + names.version;
    machine["arch"] = names.machine;
  }
  machine["compiler"] = __VERSION__;
#ifdef NDEBUG
  machine["assertions"] = false;
#else
  machine["assertions"] = true;
#endif
  return machine;
}

}  // namespace fissure::session
