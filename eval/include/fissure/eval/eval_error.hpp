#pragma once
// The one exception type of the eval library: a benchmark or stress run that cannot be set up
// or finished (a scene that does not load, an output directory that cannot be made, a failed
// child benchmark, a stress case that failed). The message is one line in the user's terms;
// the command-line program prints it as it is and exits 1 (2 for a bad argument).
#include <stdexcept>
#include <string>

namespace fissure::eval {

class EvalError : public std::runtime_error {
 public:
  /// `bad_argument`: the user's input names something that cannot be (a malformed transport
  /// spec), as opposed to a failure at run time; the command-line program exits 2 for it.
  explicit EvalError(const std::string& what, bool bad_argument = false)
      : std::runtime_error(what), bad_argument_(bad_argument) {}
  [[nodiscard]] bool bad_argument() const noexcept { return bad_argument_; }

 private:
  bool bad_argument_;
};

}  // namespace fissure::eval
