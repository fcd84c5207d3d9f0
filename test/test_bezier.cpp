// Quadratic Bezier point and tangent against hand-computed values and finite differences.
#include <gtest/gtest.h>

#include "soft_body_sim/core/bodies/bezier.h"
#include "test_util.h"

namespace soft_body_sim::test
{
namespace
{
const Vec3 kP1(0.0, 0.0, 0.0);
const Vec3 kP2(1.0, 2.0, 0.0);
const Vec3 kP3(3.0, 0.0, 1.0);

// Every value below is a sum of a few products of binary fractions (t = 0, 1/4, 1/2, 1): exact in double.
TEST(QuadraticBezier, PointMatchesHandComputedValues)
{
  // t = 0 and 1: the end control points.
  EXPECT_EQ(quadraticBezier(kP1, kP2, kP3, 0.0), kP1);
  EXPECT_EQ(quadraticBezier(kP1, kP2, kP3, 1.0), kP3);
  // t = 1/2: weights (1/4, 1/2, 1/4) -> (0 + 1/2 + 3/4, 0 + 1 + 0, 0 + 0 + 1/4).
  EXPECT_TRUE(expectNear(quadraticBezier(kP1, kP2, kP3, 0.5), Vec3(1.25, 1.0, 0.25), 0.0));
  // t = 1/4: weights (9/16, 6/16, 1/16) -> (6/16 + 3/16, 12/16, 1/16).
  EXPECT_TRUE(expectNear(quadraticBezier(kP1, kP2, kP3, 0.25), Vec3(9.0 / 16, 12.0 / 16, 1.0 / 16), 0.0));
}

TEST(QuadraticBezier, TangentMatchesHandComputedValues)
{
  // B'(0) = 2 (p2 - p1), B'(1) = 2 (p3 - p2), B'(1/2) = p3 - p1.
  EXPECT_TRUE(expectNear(quadraticBezierTangent(kP1, kP2, kP3, 0.0), Vec3(2.0, 4.0, 0.0), 0.0));
  EXPECT_TRUE(expectNear(quadraticBezierTangent(kP1, kP2, kP3, 1.0), Vec3(4.0, -4.0, 2.0), 0.0));
  EXPECT_TRUE(expectNear(quadraticBezierTangent(kP1, kP2, kP3, 0.5), Vec3(3.0, 0.0, 1.0), 0.0));
  // t = 1/4: 3/2 (1, 2, 0) + 1/2 (2, -2, 1) = (2.5, 2, 0.5).
  EXPECT_TRUE(expectNear(quadraticBezierTangent(kP1, kP2, kP3, 0.25), Vec3(2.5, 2.0, 0.5), 0.0));
}

TEST(QuadraticBezier, TangentIsTheDerivativeOfThePoint)
{
  // The central difference (B(t + e) - B(t - e)) / 2e of a quadratic is exact: its error e^2/6 B''' is 0.
  // What is left is round-off, ~ eps |B| / e = 2.2e-16 * 4 / 1e-3 ~ 1e-12; tolerance 1e-10.
  const Vec3 p1(0.3, -1.2, 2.0);
  const Vec3 p2(-0.7, 0.4, 1.1);
  const Vec3 p3(1.9, 0.8, -0.6);
  const double e = 1e-3;
  for (double t = 0.0; t <= 1.0; t += 0.125)
  {
    const Vec3 difference = (quadraticBezier(p1, p2, p3, t + e) - quadraticBezier(p1, p2, p3, t - e)) / (2.0 * e);
    EXPECT_TRUE(expectNear(quadraticBezierTangent(p1, p2, p3, t), difference, 1e-10)) << "t = " << t;
  }
}

TEST(QuadraticBezier, SamplerIncludesBothEndsAtEqualParameterSteps)
{
  const std::vector<Vec3> points = sampleQuadraticBezier(kP1, kP2, kP3, 5);
  ASSERT_EQ(points.size(), 5u);
  EXPECT_EQ(points.front(), kP1);
  EXPECT_EQ(points.back(), kP3);
  EXPECT_TRUE(expectNear(points[2], Vec3(1.25, 1.0, 0.25), 0.0));
  // Fewer than two samples still gives the two ends.
  EXPECT_EQ(sampleQuadraticBezier(kP1, kP2, kP3, 0).size(), 2u);
}

}  // namespace
}  // namespace soft_body_sim::test
