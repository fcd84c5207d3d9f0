// The input schedule as plain data, with exact stamps: inputs come out at the step their stamp falls in,
// in stamp order, ties in arrival order, late ones at the first step asked; stale and far-future stamps
// are refused at the limits' exact bounds; each source holds at most max_held inputs, the latest ones.
#include <cstdint>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/ros/input_glide.h"
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
  const std::vector<ScheduledInput> due = schedule.due(kNow + kNanosecond);
  ASSERT_EQ(due.size(), 1u);
  EXPECT_EQ(due[0].position.x(), 1.0);
  EXPECT_EQ(due[0].stamp, kNow);  // the instant it was dated to, for its glide (input_glide.h)
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

// --- the glide between an anchor's inputs (input_glide.h) ---

TEST(InputGlide, TheFirstInputIsReachedAtOnceAndLaterOnesOverTheIntervalSinceThePrevious)
{
  InputGlide glide;
  glide.add(1.0, Vec3(1, 0, 0), std::nullopt, 0.5);
  EXPECT_EQ(glide.positionAt(1.0), Vec3(1, 0, 0));
  EXPECT_FALSE(glide.movingAfter(1.0));
  // 0.05 s later (20 Hz), 2 cm on: reached 0.05 s after its stamp, linearly, from where the glide was.
  glide.add(1.05, Vec3(1.02, 0, 0), std::nullopt, 0.5);
  EXPECT_TRUE(glide.movingAfter(1.05));
  EXPECT_EQ(glide.positionAt(1.05), Vec3(1, 0, 0));
  EXPECT_NEAR(glide.positionAt(1.075).x(), 1.01, 1e-15);
  EXPECT_EQ(glide.positionAt(1.1), Vec3(1.02, 0, 0));  // exactly the input once there
  EXPECT_EQ(glide.positionAt(7.0), Vec3(1.02, 0, 0));  // inputs stopped: it holds the last
  EXPECT_FALSE(glide.movingAfter(1.1));
  // An input with the previous one's stamp: no interval, reached at once.
  glide.add(1.05, Vec3(2, 0, 0), std::nullopt, 0.5);
  EXPECT_EQ(glide.positionAt(1.05), Vec3(2, 0, 0));
}

TEST(InputGlide, AStreamAlongAPathMovesAtThePathsSpeedOneIntervalBehind)
{
  // A circle of 0.25 m, one turn in 4 s, sent at 20 Hz: at no instant faster than the path.
  const double radius = 0.25, omega = 2.0 * M_PI / 4.0, period = 0.05;
  const auto path = [&](double t) { return Vec3(radius * std::cos(omega * t), 0.0, radius * std::sin(omega * t)); };
  InputGlide glide;
  double fastest = 0.0;
  Vec3 last = path(0.0);
  glide.add(0.0, last, std::nullopt, 0.5);
  for (int k = 1; k <= 80; ++k)
  {
    glide.add(k * period, path(k * period), std::nullopt, 0.5);
    for (int j = 1; j <= 10; ++j)  // 5 ms steps
    {
      const Vec3 now = glide.positionAt(k * period + j * 0.005);
      fastest = std::max(fastest, (now - last).norm() / 0.005);
      last = now;
    }
    EXPECT_LT((last - path(k * period)).norm(), 1e-15);  // one interval after each stamp, at its input
  }
  EXPECT_LE(fastest, radius * omega * (1.0 + 1e-12));  // a chord is shorter than its arc
  EXPECT_GT(fastest, 0.99 * radius * omega);
}

TEST(InputGlide, AJitteryStreamAlongALineMovesNoFasterThanTheStream)
{
  // 1 m/s along x, sent at intervals of 38 and 62 ms in turn (a loaded publisher): where each input was
  // reached one interval after its stamp, a short interval after a long one ran at 62 / 38 = 1.6 m/s.
  std::vector<double> stamps = { 0.0 };
  for (int k = 1; k <= 40; ++k)
    stamps.push_back(stamps.back() + (k % 2 == 0 ? 0.038 : 0.062));
  InputGlide glide;
  double fastest = 0.0, clock = 0.0;
  Vec3 last = Vec3::Zero();
  for (std::size_t k = 0; k < stamps.size(); ++k)
  {
    glide.add(stamps[k], Vec3(stamps[k], 0, 0), std::nullopt, 0.5);
    const double next = k + 1 < stamps.size() ? stamps[k + 1] : stamps[k] + 0.2;
    for (; clock + 0.005 <= next; clock += 0.005)  // 5 ms steps up to the next input
    {
      const Vec3 now = glide.positionAt(clock + 0.005);
      fastest = std::max(fastest, (now - last).norm() / 0.005);
      last = now;
    }
  }
  EXPECT_LE(fastest, 1.0 + 1e-9);
  EXPECT_GT(fastest, 0.99);
  EXPECT_EQ(last, Vec3(stamps.back(), 0, 0));
}

TEST(InputGlide, AfterAPauseLongerThanTheLongestIntervalAnInputIsReachedOverThatInterval)
{
  InputGlide glide;
  glide.add(0.0, Vec3::Zero(), std::nullopt, 0.25);
  glide.add(10.0, Vec3(1, 0, 0), std::nullopt, 0.25);
  EXPECT_NEAR(glide.positionAt(10.125).x(), 0.5, 1e-12);
  EXPECT_EQ(glide.positionAt(10.25), Vec3(1, 0, 0));
  // Late: stamped 0.1 s before the step that reads it, it is 0.1 s along by then.
  glide.add(10.4, Vec3(2, 0, 0), std::nullopt, 0.25);
  EXPECT_NEAR(glide.positionAt(10.5).x(), 1.4, 1e-12);
}

TEST(InputGlide, AnOrientationTurnsBySlerpWithThePosition)
{
  InputGlide glide;
  const Eigen::Quaterniond start = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  glide.add(0.0, Vec3::Zero(), start, 0.5);
  glide.add(0.1, Vec3(1, 0, 0), turned, 0.5);
  const std::optional<Eigen::Quaterniond> half = glide.orientationAt(0.15);
  ASSERT_TRUE(half);
  EXPECT_NEAR(half->angularDistance(start), M_PI / 4, 1e-12);
  EXPECT_NEAR(half->angularDistance(turned), M_PI / 4, 1e-12);
  EXPECT_TRUE(glide.orientationAt(0.2)->isApprox(turned, 0.0));
  // Inputs without an orientation leave it to the anchor.
  glide.add(0.3, Vec3(2, 0, 0), std::nullopt, 0.5);
  EXPECT_FALSE(glide.orientationAt(0.35));
}

TEST(InputGlide, AnInputAfterAPauseIsReachedAtOnceWhereATargetStartsAMoveOfItsOwn)
{
  InputGlide glide;
  glide.addAfterPauseAtOnce(0.0, Vec3::Zero(), 0.25);
  glide.addAfterPauseAtOnce(0.05, Vec3(0.1, 0, 0), 0.25);  // within the stream: glides
  EXPECT_NEAR(glide.positionAt(0.075).x(), 0.05, 1e-15);
  glide.addAfterPauseAtOnce(10.0, Vec3(1, 0, 0), 0.25);  // after 10 s: at once
  EXPECT_EQ(glide.positionAt(10.0), Vec3(1, 0, 0));
  EXPECT_FALSE(glide.movingAfter(10.0));
}

// --- a holder on a tf frame (InputGlide::follow) ---

/// The fastest [m/s] a holder moves from 5 ms step to step over 4 s while its tf frame runs along a circle
/// of 0.25 m (one turn in 4 s, 0.39 m/s), broadcast at 20 Hz stamped `lead` [s] ahead of the instant it
/// is for and seen by the first step that ends `latency` [s] or more after it is sent (negative lead: late).
double fastestHolder(double lead, double latency, double max_interval)
{
  const double radius = 0.25, omega = 2.0 * M_PI / 4.0, period = 0.05, dt = 0.005;
  const auto path = [&](double t) { return Vec3(radius * std::cos(omega * t), 0.0, radius * std::sin(omega * t)); };
  InputGlide glide;
  double fastest = 0.0;
  Vec3 previous = path(0.0);
  for (int j = 1; j <= 800; ++j)
  {
    const double start = (j - 1) * dt, end = j * dt;
    // The newest transform tf has at `end` (sent at its stamp - lead, one per period) and, if it has one
    // on both sides of `end`, its interpolation there.
    const double newest = std::floor((end - latency) / period + 1e-9) * period + lead;
    if (end <= newest)
    {
      const double k = std::floor((end - lead) / period);
      const double s = (end - lead) / period - k;
      const Vec3 exact = (1.0 - s) * path(k * period + lead) + s * path((k + 1) * period + lead);
      if (glide.onFrame(end, exact, Eigen::Quaterniond::Identity()))
      {
        fastest = j > 20 ? std::max(fastest, (exact - previous).norm() / dt) : fastest;
        previous = exact;
        continue;
      }
    }
    glide.followNewest(start, newest, path(newest), Eigen::Quaterniond::Identity(), max_interval);
    const Vec3 now = glide.positionAt(end);
    if (j > 20)
      fastest = std::max(fastest, (now - previous).norm() / dt);
    previous = now;
  }
  return fastest / (radius * omega);
}

TEST(InputGlide, AHolderOnALateFrameGlidesAtTheFramesSpeedWhereReachingEachTransformJumped)
{
  // Stamped now and seen 1 ms later, as robot_state_publisher's or a driver's frames are: each step
  // ends past the newest transform.
  EXPECT_LE(fastestHolder(0.0, 0.001, 0.5), 1.0 + 1e-9);
  EXPECT_GT(fastestHolder(0.0, 0.001, 0.5), 0.99);
  // ~max_input_interval 0: each transform reached in the step that sees it, 2 cm in 5 ms (ten times).
  EXPECT_GT(fastestHolder(0.0, 0.001, 0.0), 9.0);
  // Stamped 0.1 s ahead (send_targets.py's lead): tf interpolates at each step's end, exactly.
  EXPECT_LE(fastestHolder(0.1, 0.001, 0.5), 1.0 + 1e-9);
  EXPECT_EQ(fastestHolder(0.1, 0.001, 0.5), fastestHolder(0.1, 0.001, 0.0));
  // Stamped 2 ms ahead and seen at once: the step that sees a transform ends before its stamp, the next
  // nine after it. Late and not late in turn, it glides on rather than jumping back onto tf's pose (it
  // catches up with the frame at up to 1.25 times its speed).
  EXPECT_LE(fastestHolder(0.002, 0.0, 0.5), 1.25 + 1e-9);
  EXPECT_GT(fastestHolder(0.002, 0.0, 0.0), 9.0);
}

TEST(InputGlide, AHolderBehindALateFrameCatchesUpAtAQuarterFasterThanTheFrame)
{
  // 1 m/s along x, broadcast at 20 Hz stamped now and seen at once, but none from 1.0 to 1.3 s (a
  // publisher's hiccup): the holder rests at the last, then glides behind the resumed stream. It catches up
  // to one interval behind within two seconds, never faster than 1.25 m/s.
  const double period = 0.05, dt = 0.005;
  const auto sent = [&](double t) {
    const double last = std::floor(t / period + 1e-9) * period;
    return last > 1.0 + 1e-9 && last < 1.3 - 1e-9 ? 1.0 : last;
  };
  InputGlide glide;
  double fastest = 0.0, previous = 0.0;
  for (int j = 1; j <= 800; ++j)
  {
    const double start = (j - 1) * dt, end = j * dt;
    const double stamp = sent(end);
    // tf has the frame at `end` once its newest is stamped there or later: at x = end.
    if (stamp < end || !glide.onFrame(end, Vec3(end, 0, 0), Eigen::Quaterniond::Identity()))
      glide.followNewest(start, stamp, Vec3(stamp, 0, 0), Eigen::Quaterniond::Identity(), 0.5);
    const double now = glide.positionAt(end).x();
    fastest = std::max(fastest, (now - previous) / dt);
    previous = now;
    if (end > 3.3)
    {
      EXPECT_GE(now, end - period - dt - 1e-9) << end;  // at most an interval and a step behind
    }
  }
  EXPECT_LE(fastest, 1.25 + 1e-9);
  EXPECT_GT(fastest, 1.2);
}

TEST(InputGlide, AFrameThatFallsBehindGoesOnAlongItsPathFromTheExactPose)
{
  // On tf's pose at 1.0, then tf's newest is stamped 1.02 when the step to 1.025 ends: the holder goes on
  // along the path, reaching 1.02's pose at 1.02, and holds it while nothing newer comes.
  InputGlide glide;
  EXPECT_TRUE(glide.onFrame(1.0, Vec3(1, 0, 0), Eigen::Quaterniond::Identity()));
  EXPECT_EQ(glide.positionAt(1.0), Vec3(1, 0, 0));
  glide.followNewest(1.0, 1.02, Vec3(1.02, 0, 0), Eigen::Quaterniond::Identity(), 0.5);
  EXPECT_NEAR(glide.positionAt(1.01).x(), 1.01, 1e-12);
  EXPECT_EQ(glide.positionAt(1.025), Vec3(1.02, 0, 0));
  glide.followNewest(1.025, 1.02, Vec3(1.02, 0, 0), Eigen::Quaterniond::Identity(), 0.5);
  EXPECT_EQ(glide.positionAt(1.03), Vec3(1.02, 0, 0));
  // The next, stamped 1.07 and seen in the step from 1.08: 5 cm in 0.05 s, glided over 0.05 s from 1.08.
  glide.followNewest(1.08, 1.07, Vec3(1.07, 0, 0), Eigen::Quaterniond::Identity(), 0.5);
  EXPECT_NEAR(glide.positionAt(1.105).x(), 1.045, 1e-12);
  EXPECT_EQ(glide.positionAt(1.14), Vec3(1.07, 0, 0));
  // tf has it on both sides again: the holder is off the frame until its glide ends on tf's pose.
  EXPECT_FALSE(glide.onFrame(1.11, Vec3(1.08, 0, 0), Eigen::Quaterniond::Identity()));
  EXPECT_TRUE(glide.onFrame(1.2, Vec3(1.07, 0, 0), Eigen::Quaterniond::Identity()));  // the frame stopped there
}

}  // namespace
}  // namespace soft_body_sim
