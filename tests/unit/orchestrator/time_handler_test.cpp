// TimeHandler (Kahan summation), dt policy and sub-cycling plan.
#include <cmath>

#include <gtest/gtest.h>

#include <coredem/orchestrator/time_handler.h>

using namespace coredem::orchestrator;

// 10^6 steps of 1e-6 s must land on t = 1 s. Naive summation drifts by ~1e-11 here;
// the compensated sum stays within a few ulps (tolerance 4e-16 s, about 2 ulp of 1.0).
TEST(TimeHandler, ManyTinyTimesteps) {
  TimeHandler th;
  double naive = 0.0;
  const double dt = 1e-6;
  for (int i = 0; i < 1000000; ++i) {
    th.advance(dt);
    naive += dt;
  }
  EXPECT_NEAR(th.time() - th.compensation(), 1.0, 4e-16);
  EXPECT_TRUE(th.reached(1.0));
  EXPECT_GT(std::abs(naive - 1.0), 1e-12); // the naive sum really does drift
}

TEST(TimeHandler, ManyTinyStepsWithRunLoopLandOnEnd) {
  // The run loop: ask the policy for dt until the end is reached; exactly 10^6 steps.
  DtPolicyConfig cfg;
  cfg.dt = 1e-7;
  DtPolicy policy(cfg);
  TimeHandler th;
  long steps = 0;
  while (!th.reached(0.1)) {
    th.advance(policy.next(-1.0, th.remaining(0.1)));
    ++steps;
  }
  EXPECT_EQ(steps, 1000000);
  EXPECT_NEAR(th.time(), 0.1, 1e-16);
}

TEST(TimeHandler, RestoredStateContinuesBitwise) {
  TimeHandler a;
  for (int i = 0; i < 1000; ++i) {
    a.advance(1.3e-4);
  }
  TimeHandler b(a.time(), a.compensation());
  for (int i = 0; i < 1000; ++i) {
    a.advance(1.3e-4);
    b.advance(1.3e-4);
  }
  EXPECT_EQ(a.time(), b.time());
  EXPECT_EQ(a.compensation(), b.compensation());
}

TEST(TimeEquals, RelativeTolerance) {
  EXPECT_TRUE(timeEquals(1.0, 1.0 + 5e-13));
  EXPECT_FALSE(timeEquals(1.0, 1.0 + 5e-12));
  EXPECT_TRUE(timeEquals(0.0, 1e-13));
}

TEST(DtPolicy, FixedClipsLastStepToEnd) {
  DtPolicyConfig cfg;
  cfg.dt = 0.3;
  DtPolicy p(cfg);
  TimeHandler th;
  std::vector<double> dts;
  while (!th.reached(1.0)) {
    dts.push_back(p.next(-1, th.remaining(1.0)));
    th.advance(dts.back());
  }
  ASSERT_EQ(dts.size(), 4u);
  EXPECT_DOUBLE_EQ(dts[3], 0.1);
  EXPECT_NEAR(th.time(), 1.0, 1e-15);
}

TEST(DtPolicy, CourantAdaptsWithinBounds) {
  DtPolicyConfig cfg;
  cfg.kind = DtPolicyConfig::Kind::Courant;
  cfg.dt = 1e-3;
  cfg.dtMin = 1e-4;
  cfg.dtMax = 2e-3;
  cfg.courant = 0.5;
  cfg.maxGrowth = 1.2;
  DtPolicy p(cfg);
  EXPECT_DOUBLE_EQ(p.next(-1.0, 10.0), 1e-3);  // no report yet: initial dt
  EXPECT_DOUBLE_EQ(p.next(1.0, 10.0), 5e-4);   // Co = 1 -> halve
  EXPECT_DOUBLE_EQ(p.next(0.1, 10.0), 6e-4);   // Co = 0.1 -> growth limited to 1.2
  EXPECT_DOUBLE_EQ(p.next(100.0, 10.0), 1e-4); // clamped to dt_min
  EXPECT_DOUBLE_EQ(p.next(0.0, 10.0), 1.2e-4); // no flow: grow by max_growth
  for (int i = 0; i < 50; ++i) {
    p.next(0.0, 10.0);
  }
  EXPECT_DOUBLE_EQ(p.next(0.0, 10.0), 2e-3);   // clamped to dt_max
  EXPECT_DOUBLE_EQ(p.next(0.5, 1e-3), 1e-3);   // clipped to the remaining time
  EXPECT_DOUBLE_EQ(p.next(0.5, 3e-3), 1.5e-3); // < 2 steps left: two equal steps, no sliver
}

TEST(SubcyclePlan, CeilAndExactProduct) {
  auto a = planSubcycles(1e-4, 3e-6);
  EXPECT_EQ(a.nSub, 34); // 33.33 -> 34
  EXPECT_LE(a.dtDem, 3e-6);
  EXPECT_NEAR(a.dtDem * double(a.nSub), 1e-4, 1e-4 * 1e-15);
  // An exact ratio up to round-off is not rounded up (1e-4 / 2e-6 = 50.000000000000007).
  auto b = planSubcycles(1e-4, 2e-6);
  EXPECT_EQ(b.nSub, 50);
  // Δt_DEM,max larger than Δt_CFD: one sub-step.
  auto c = planSubcycles(1e-5, 1e-3);
  EXPECT_EQ(c.nSub, 1);
  EXPECT_EQ(c.dtDem, 1e-5);
  // Just above an integer ratio rounds up.
  auto d = planSubcycles(1e-4 * (1.0 + 1e-9), 2e-6);
  EXPECT_EQ(d.nSub, 51);
}
