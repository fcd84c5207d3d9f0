// The main of every core test: GoogleTest's, plus a listener that fails any test during which the
// divergence guard caught a body, unless the test called expectGuardEvents(). The guard is a safety net
// for users; in a test it would turn an explosion into a log line that nobody reads.
#include <cstdint>

#include <gtest/gtest.h>

#include "soft_body_sim/core/guard.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
bool guard_events_expected = false;

class GuardEventChecker : public ::testing::EmptyTestEventListener
{
  void OnTestStart(const ::testing::TestInfo&) override
  {
    guard_events_expected = false;
    events_at_start_ = divergenceEventsInProcess();
  }

  // As GoogleTest's own leak checker (samples/sample10_unittest.cc): a failure raised here counts
  // against the test that just ended.
  void OnTestEnd(const ::testing::TestInfo&) override
  {
    const std::int64_t events = divergenceEventsInProcess() - events_at_start_;
    EXPECT_TRUE(guard_events_expected || events == 0)
        << "the divergence guard caught " << events
        << " time(s) in a test that is not about the guard (call expectGuardEvents() in one that is)";
  }

  std::int64_t events_at_start_ = 0;
};

}  // namespace

void expectGuardEvents() { guard_events_expected = true; }

}  // namespace soft_body_sim::test

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ::testing::UnitTest::GetInstance()->listeners().Append(new soft_body_sim::test::GuardEventChecker);
  return RUN_ALL_TESTS();
}
