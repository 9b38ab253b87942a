// Ctrl-C while a session runs (session/sigint_flag.hpp): the first SIGINT asks for the stop, a
// second one (an impatient user, `timeout -s INT` twice) must not kill the process while it
// ramps out and writes its outputs; only a third ends it at once.
#include "fissure/session/sigint_flag.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>

namespace fissure::session {
namespace {

TEST(SigintFlag, FirstSigintSetsTheFlag) {
  const SigintFlag sigint;
  ASSERT_FALSE(SigintFlag::raised());
  std::raise(SIGINT);
  EXPECT_TRUE(SigintFlag::raised());
  EXPECT_EQ(SigintFlag::count(), 1);
}

TEST(SigintFlag, SecondSigintLeavesTheProcessRunningToFinishItsOutputs) {
  const SigintFlag sigint;
  std::raise(SIGINT);
  std::raise(SIGINT);
  EXPECT_TRUE(SigintFlag::raised());
  EXPECT_EQ(SigintFlag::count(), 2);
}

TEST(SigintFlagDeathTest, SecondSigintSaysWhatHappensAndTheThirdEndsTheProcess) {
  EXPECT_EXIT(
      {
        const SigintFlag sigint;
        std::raise(SIGINT);
        std::raise(SIGINT);
        std::raise(SIGINT);
        std::exit(0);
      },
      testing::KilledBySignal(SIGINT), "already stopping.*writing the outputs.*Ctrl-C again");
}

TEST(SigintFlag, TheFlagIsClearedForTheNextCommandAndThePreviousHandlerComesBack) {
  {
    const SigintFlag sigint;
    std::raise(SIGINT);
  }
  struct sigaction now {};
  sigaction(SIGINT, nullptr, &now);
  EXPECT_EQ(now.sa_handler, SIG_DFL);
  const SigintFlag again;
  EXPECT_FALSE(SigintFlag::raised());
  EXPECT_EQ(SigintFlag::count(), 0);
}

}  // namespace
}  // namespace fissure::session
