#pragma once
// The one exception type of the session library: a session that cannot be set up or run (no
// device, a rate that does not divide, an unwritable output directory, a refused peer). The
// message is one line in the user's terms; the command-line program prints it as it is.
#include <stdexcept>
#include <string>

namespace fissure::session {

class SessionError : public std::runtime_error {
 public:
  /// `bad_argument`: the user's input names something that cannot be (a malformed transport
  /// spec), as opposed to a failure at run time; the command-line program exits 2 for it.
  explicit SessionError(const std::string& what, bool bad_argument = false)
      : std::runtime_error(what), bad_argument_(bad_argument) {}
  [[nodiscard]] bool bad_argument() const noexcept { return bad_argument_; }

 private:
  bool bad_argument_;
};

}  // namespace fissure::session
