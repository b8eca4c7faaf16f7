// TimeHandler: sub-step count and drift-free accumulation (preCICE ManyTinyTimesteps).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "coredem/dem/time_handler.h"

using coredem::dem::TimeHandler;

TEST(TimeHandler, ManyTinySubSteps) {
  // 10^6 sub-steps of 1e-7 s must give 0.1 s to ~1 ulp; naive summation drifts by ~1e-11.
  const int n = 1000000;
  const double dt = 0.1 / n;
  TimeHandler t;
  double naive = 0.0;
  for (int i = 0; i < n; ++i) {
    t.add(dt);
    naive += dt;
  }
  EXPECT_NEAR(t.time(), 0.1, 2e-17);
  EXPECT_GT(std::fabs(naive - 0.1), 1e-13); // shows the test would catch plain summation
  EXPECT_TRUE(coredem::dem::timeEquals(t.time(), 0.1));
}

TEST(TimeHandler, WindowsOfSubStepsEndExactly) {
  // 1000 CFD windows of 1e-4 s with n_sub = 57: the time after each window matches k·Δt_CFD.
  TimeHandler t;
  const double dtCfd = 1e-4;
  const int nSub = TimeHandler::subStepsFor(dtCfd, 1.77e-6);
  EXPECT_EQ(nSub, 57);
  for (int k = 1; k <= 1000; ++k) {
    for (int s = 0; s < nSub; ++s)
      t.add(dtCfd / nSub);
    ASSERT_NEAR(t.time(), k * dtCfd, 4 * std::numeric_limits<double>::epsilon() * k * dtCfd)
        << "window " << k;
  }
}

TEST(TimeHandler, SubStepsFor) {
  EXPECT_EQ(TimeHandler::subStepsFor(1e-4, 1e-5), 10); // exact ratio
  EXPECT_EQ(TimeHandler::subStepsFor(1e-4, 1e-5 * (1 + 1e-15)), 10);
  EXPECT_EQ(TimeHandler::subStepsFor(1e-4, 0.99e-5), 11);
  EXPECT_EQ(TimeHandler::subStepsFor(1e-6, 1e-5), 1);
  EXPECT_LE(1e-4 / TimeHandler::subStepsFor(1e-4, 1.61e-6), 1.61e-6);
  EXPECT_THROW(TimeHandler::subStepsFor(-1.0, 1e-5), coredem::UserError);
  EXPECT_THROW(TimeHandler::subStepsFor(1e-4, 0.0), coredem::UserError);
}

TEST(TimeHandler, RestoreIsBitwise) {
  TimeHandler a;
  for (int i = 0; i < 1000; ++i)
    a.add(1.3e-6);
  TimeHandler b;
  b.restore(a.time(), a.compensation());
  for (int i = 0; i < 1000; ++i) {
    a.add(1.3e-6);
    b.add(1.3e-6);
  }
  EXPECT_EQ(a.time(), b.time());
}
