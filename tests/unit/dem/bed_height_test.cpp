// bedHeight (coredem/dem/bed_height.h): the DEM server's `bed_height_m` diagnostic.
#include <gtest/gtest.h>

#include <coredem/dem/bed_height.h>

using coredem::dem::bedHeight;

namespace {

/// A packed column of `layers` x 10 x 10 spheres of diameter d, stacked along `up` from `base`.
void lattice(int layers, double d, int up, double base, std::vector<double>& pos,
             std::vector<double>& radius) {
  for (int l = 0; l < layers; ++l) {
    for (int i = 0; i < 10; ++i) {
      for (int j = 0; j < 10; ++j) {
        double p[3];
        const int a = (up + 1) % 3, b = (up + 2) % 3;
        p[up] = base + (l + 0.5) * d;
        p[a] = (i + 0.5) * d;
        p[b] = (j + 0.5) * d;
        pos.insert(pos.end(), p, p + 3);
        radius.push_back(0.5 * d);
      }
    }
  }
}

} // namespace

// L layers of diameter d: L d, whatever the vertical axis and the base elevation (1e-12 m).
TEST(BedHeight, PackedLayersGiveLayersTimesDiameter) {
  for (int up = 0; up < 3; ++up) {
    std::vector<double> pos, radius;
    lattice(4, 1e-3, up, 0.004, pos, radius);
    std::array<double, 3> g{0.0, 0.0, 0.0};
    g[up] = -9.81;
    EXPECT_NEAR(bedHeight(pos, radius, radius.size(), g), 4e-3, 1e-12) << "axis " << up;
  }
}

// Fewer than 5 % of the particles far above the bed do not change it; no particles or no
// gravity give 0.
TEST(BedHeight, IgnoresTheHighestFivePercentAndEmptyCases) {
  std::vector<double> pos, radius;
  lattice(4, 1e-3, 1, 0.0, pos, radius);
  for (int k = 0; k < 10; ++k) { // 10 of 410 particles splashed 5 cm up
    pos.insert(pos.end(), {0.001 * k, 0.05, 0.0});
    radius.push_back(0.5e-3);
  }
  EXPECT_NEAR(bedHeight(pos, radius, radius.size(), {0.0, -9.81, 0.0}), 4e-3, 1e-12);
  EXPECT_EQ(bedHeight({}, {}, 0, {0.0, -9.81, 0.0}), 0.0);
  EXPECT_EQ(bedHeight(pos, radius, radius.size(), {0.0, 0.0, 0.0}), 0.0);
}
