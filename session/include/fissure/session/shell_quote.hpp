#pragma once
// Quoting for the few places the app hands a command line to /bin/sh (system(), popen()):
// the session plot and `fissure bench all`'s children, report generator and git queries.
#include <string>

namespace fissure::session {

// `s` single-quoted for /bin/sh, any embedded ' written as '\'' — safe for every byte string.
std::string shell_quote(const std::string& s);

}  // namespace fissure::session
