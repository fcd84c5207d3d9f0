// The input schedule as plain data, with exact stamps: inputs come out at the step their stamp falls in,
// in stamp order, ties in arrival order, late ones at the first step asked; stale and far-future stamps
// are refused at the limits' exact bounds; each source holds at most max_held inputs, the latest ones.
#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

#include "soft_body_sim/ros/input_schedule.h"

namespace soft_body_sim
{
namespace
{
using Verdict = InputSchedule::Verdict;

const ros::Time kNow(100, 0);            // the ROS clock at every push unless a test says otherwise
const ros::Duration kStep(0.01);         // [s] the steps of these tests
const ros::Duration kNanosecond(0, 1);

ScheduledInput anchorInput(int anchor, double x)
{
  ScheduledInput input;
  input.anchor = anchor;
  input.position = Vec3(x, 0.0, 0.0);
  return input;
}

ScheduledInput targetInput(const std::string& body, double x)
{
  ScheduledInput input;
  input.kind = ScheduledInput::Kind::Target;
  input.body = body;
  input.position = Vec3(x, 0.0, 0.0);
  return input;
}

std::vector<double> xs(const std::vector<ScheduledInput>& inputs)
{
  std::vector<double> out;
  for (const ScheduledInput& input : inputs)
    out.push_back(input.position.x());
  return out;
}

TEST(InputSchedule, InputsComeOutAtTheStepTheirStampFallsInInStampOrder)
{
  InputSchedule schedule;
  const ros::Time t0 = kNow;
  schedule.push(kNow, t0 + ros::Duration(0.025), anchorInput(0, 3.0));  // step [0.02, 0.03)
  schedule.push(kNow, t0 + ros::Duration(0.005), anchorInput(0, 1.0));  // step [0, 0.01)
  schedule.push(kNow, t0 + ros::Duration(0.005), anchorInput(1, 2.0));  // same stamp, arrived later
  schedule.push(kNow, t0 + ros::Duration(0.020), anchorInput(0, 4.0));  // exactly a step boundary: [0.02, 0.03)
  schedule.push(kNow, t0 - ros::Duration(1.0), anchorInput(2, 0.5));    // late: the first step asked

  std::vector<ScheduledInput> first = schedule.due(t0 + kStep);
  ASSERT_EQ(first.size(), 3u);
  EXPECT_EQ(first[0].anchor, 2);
  EXPECT_EQ(first[1].position.x(), 1.0);
  EXPECT_EQ(first[2].position.x(), 2.0);
  EXPECT_TRUE(schedule.due(t0 + kStep + kStep).empty());
  std::vector<ScheduledInput> third = schedule.due(t0 + kStep + kStep + kStep);
  ASSERT_EQ(third.size(), 2u);
  EXPECT_EQ(third[0].position.x(), 4.0);
  EXPECT_EQ(third[1].position.x(), 3.0);
  EXPECT_EQ(schedule.size(), 0u);
}

TEST(InputSchedule, EqualStampsOfDifferentSourcesComeOutInArrivalOrder)
{
  InputSchedule schedule;
  const ros::Time stamp = kNow + ros::Duration(0.001);
  schedule.push(kNow, stamp, targetInput("creature", 1.0));
  schedule.push(kNow, stamp, anchorInput(3, 2.0));
  schedule.push(kNow, stamp, anchorInput(0, 3.0));
  schedule.push(kNow, stamp, targetInput("creature", 4.0));
  EXPECT_EQ(xs(schedule.due(kNow + kStep)), (std::vector<double>{ 1.0, 2.0, 3.0, 4.0 }));
}

TEST(InputSchedule, AStampZeroMeansNow)
{
  InputSchedule schedule;
  const InputSchedule::Admission admission = schedule.push(kNow, ros::Time(0), anchorInput(0, 1.0));
  EXPECT_EQ(admission.verdict, Verdict::Held);
  EXPECT_EQ(admission.offset, 0.0);
  EXPECT_TRUE(schedule.due(kNow).empty());  // a step ending at now: stamped now falls in the one after
  EXPECT_EQ(xs(schedule.due(kNow + kNanosecond)), std::vector<double>{ 1.0 });
}

TEST(InputSchedule, AStaleStampIsDroppedBeyondMaxAgeAndGoesToTheNextStepWithinIt)
{
  InputLimits limits;
  limits.max_age = 0.5;
  InputSchedule schedule(limits);
  // Exactly max_age behind: still held, and late, so due at the first step asked.
  const InputSchedule::Admission at_bound = schedule.push(kNow, kNow - ros::Duration(0.5), anchorInput(0, 1.0));
  EXPECT_EQ(at_bound.verdict, Verdict::Held);
  EXPECT_EQ(at_bound.offset, -0.5);
  // One nanosecond more: stale.
  const InputSchedule::Admission stale =
      schedule.push(kNow, kNow - ros::Duration(0.5) - kNanosecond, anchorInput(0, 2.0));
  EXPECT_EQ(stale.verdict, Verdict::Stale);
  EXPECT_FALSE(stale.evicted);
  EXPECT_NEAR(stale.offset, -0.500000001, 1e-12);
  // A stamp from 1970 (seconds since the epoch = 1) against a clock at 100 s.
  EXPECT_EQ(schedule.push(kNow, ros::Time(1, 0), anchorInput(0, 3.0)).verdict, Verdict::Stale);
  EXPECT_EQ(schedule.size(), 1u);
  EXPECT_EQ(xs(schedule.due(kNow - ros::Duration(0.4))), std::vector<double>{ 1.0 });
}

TEST(InputSchedule, AFarFutureStampIsDroppedBeyondMaxLeadAndHeldUntilItsStepWithinIt)
{
  InputLimits limits;
  limits.max_lead = 2.0;
  InputSchedule schedule(limits);
  const InputSchedule::Admission at_bound = schedule.push(kNow, kNow + ros::Duration(2.0), anchorInput(0, 1.0));
  EXPECT_EQ(at_bound.verdict, Verdict::Held);
  EXPECT_EQ(at_bound.offset, 2.0);
  const InputSchedule::Admission ahead = schedule.push(kNow, kNow + ros::Duration(2.0) + kNanosecond, anchorInput(0, 2.0));
  EXPECT_EQ(ahead.verdict, Verdict::TooFarAhead);
  EXPECT_NEAR(ahead.offset, 2.000000001, 1e-12);
  // The largest stamp a message can hold, 136 years ahead: refused, without ros::Duration's overflow.
  const ros::Time last(std::numeric_limits<std::uint32_t>::max(), 999999999);
  const InputSchedule::Admission latest = schedule.push(kNow, last, anchorInput(0, 3.0));
  EXPECT_EQ(latest.verdict, Verdict::TooFarAhead);
  EXPECT_GT(latest.offset, 4.0e9);
  // The held one waits for its step: not in the step ending at its stamp, in the next.
  EXPECT_TRUE(schedule.due(kNow + ros::Duration(2.0)).empty());
  EXPECT_EQ(xs(schedule.due(kNow + ros::Duration(2.0) + kStep)), std::vector<double>{ 1.0 });
}

TEST(InputSchedule, WithoutAClockStampsAreHeldUnjudged)
{
  // /use_sim_time before the first /clock: ros::Time::now() is 0, so nothing can be called stale or early.
  InputLimits limits;
  limits.max_age = 0.1;
  limits.max_lead = 0.1;
  InputSchedule schedule(limits);
  const ros::Time zero(0, 0);
  const InputSchedule::Admission ahead = schedule.push(zero, ros::Time(1700000000, 0), anchorInput(0, 1.0));
  EXPECT_EQ(ahead.verdict, Verdict::Held);
  EXPECT_EQ(ahead.offset, 0.0);
  EXPECT_EQ(schedule.push(zero, ros::Time(0), anchorInput(1, 2.0)).verdict, Verdict::Held);
  EXPECT_EQ(xs(schedule.due(ros::Time(1, 0))), std::vector<double>{ 2.0 });  // stamp 0: the first step
  EXPECT_TRUE(schedule.due(ros::Time(1700000000, 0)).empty());
  EXPECT_EQ(xs(schedule.due(ros::Time(1700000000, 1))), std::vector<double>{ 1.0 });
}

TEST(InputSchedule, EachSourceHoldsAtMostMaxHeldInputsKeepingTheLatestStamps)
{
  InputLimits limits;
  limits.max_held = 3;
  InputSchedule schedule(limits);
  std::vector<bool> evicted;
  for (int k = 1; k <= 5; ++k)  // anchor 0 at 1, 2, ... 5 ms ahead
    evicted.push_back(schedule.push(kNow, kNow + ros::Duration(0.001 * k), anchorInput(0, k)).evicted);
  EXPECT_EQ(evicted, (std::vector<bool>{ false, false, false, true, true }));
  // Full, a stamp earlier than every held one is itself the earliest: it goes, the held ones stay.
  const InputSchedule::Admission early = schedule.push(kNow, kNow, anchorInput(0, 0.0));
  EXPECT_EQ(early.verdict, Verdict::Held);
  EXPECT_TRUE(early.evicted);
  // Other sources have their own room: anchor 1 and the creature's target are not cut by anchor 0.
  for (int k = 1; k <= 3; ++k)
  {
    EXPECT_FALSE(schedule.push(kNow, kNow + ros::Duration(0.0001 * k), anchorInput(1, 10.0 + k)).evicted);
    EXPECT_FALSE(schedule.push(kNow, kNow + ros::Duration(0.0001 * k), targetInput("creature", 20.0 + k)).evicted);
  }
  EXPECT_EQ(schedule.size(), 9u);
  EXPECT_EQ(xs(schedule.due(kNow + kStep)),
            (std::vector<double>{ 11.0, 21.0, 12.0, 22.0, 13.0, 23.0, 3.0, 4.0, 5.0 }));
}

TEST(InputSchedule, LimitsChangeForLaterPushesAndClearEmptiesEverySource)
{
  InputSchedule schedule;
  EXPECT_EQ(schedule.limits().max_age, 1.0);
  EXPECT_EQ(schedule.limits().max_lead, 5.0);
  EXPECT_EQ(schedule.limits().max_held, 1000u);
  EXPECT_EQ(schedule.push(kNow, kNow - ros::Duration(0.9), anchorInput(0, 1.0)).verdict, Verdict::Held);
  InputLimits strict;
  strict.max_age = 0.1;
  schedule.setLimits(strict);
  EXPECT_EQ(schedule.push(kNow, kNow - ros::Duration(0.9), anchorInput(0, 2.0)).verdict, Verdict::Stale);
  schedule.push(kNow, kNow, targetInput("creature", 3.0));
  EXPECT_EQ(schedule.size(), 2u);
  schedule.clear();
  EXPECT_EQ(schedule.size(), 0u);
  EXPECT_TRUE(schedule.due(kNow + ros::Duration(10.0)).empty());
}

}  // namespace
}  // namespace soft_body_sim
