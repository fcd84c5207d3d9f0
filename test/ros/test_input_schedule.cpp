// The input schedule as plain data: inputs come out at the step their stamp falls in, in stamp order,
// ties in arrival order, late ones at the first step asked.
#include <gtest/gtest.h>

#include "soft_body_sim/ros/input_schedule.h"

namespace soft_body_sim
{
namespace
{
ScheduledInput anchorInput(int anchor, double x)
{
  ScheduledInput input;
  input.anchor = anchor;
  input.position = Vec3(x, 0.0, 0.0);
  return input;
}

TEST(InputSchedule, InputsComeOutAtTheStepTheirStampFallsInInStampOrder)
{
  InputSchedule schedule;
  const ros::Time t0(100, 0);
  const ros::Duration dt(0.01);
  schedule.push(t0 + ros::Duration(0.025), anchorInput(0, 3.0));  // step [0.02, 0.03)
  schedule.push(t0 + ros::Duration(0.005), anchorInput(0, 1.0));  // step [0, 0.01)
  schedule.push(t0 + ros::Duration(0.005), anchorInput(1, 2.0));  // same stamp, arrived later
  schedule.push(t0 + ros::Duration(0.020), anchorInput(0, 4.0));  // exactly a step boundary: [0.02, 0.03)
  schedule.push(t0 - ros::Duration(1.0), anchorInput(2, 0.5));    // late: the first step asked

  std::vector<ScheduledInput> first = schedule.due(t0 + dt);
  ASSERT_EQ(first.size(), 3u);
  EXPECT_EQ(first[0].anchor, 2);
  EXPECT_EQ(first[1].position.x(), 1.0);
  EXPECT_EQ(first[2].position.x(), 2.0);
  EXPECT_TRUE(schedule.due(t0 + dt + dt).empty());
  std::vector<ScheduledInput> third = schedule.due(t0 + dt + dt + dt);
  ASSERT_EQ(third.size(), 2u);
  EXPECT_EQ(third[0].position.x(), 4.0);
  EXPECT_EQ(third[1].position.x(), 3.0);
  EXPECT_EQ(schedule.size(), 0u);
}

}  // namespace
}  // namespace soft_body_sim
