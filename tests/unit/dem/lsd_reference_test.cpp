// LSD pair contact against reference data: data/lsd_contact.yaml holds inputs and
// expected force/torque/δ_t computed by an independent Python implementation of docs/physics.md
// §2.1 (data/make_lsd_reference.py).
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "coredem/dem/kernels/damping.h"
#include "coredem/dem/kernels/lsd_contact.h"

using namespace coredem::dem::kernels;

namespace {
Vec3 vec(const YAML::Node& n) {
  return Vec3{n[0].as<double>(), n[1].as<double>(), n[2].as<double>()};
}

void expectVec(const Vec3& got, const Vec3& want, double eps, const std::string& what) {
  const double scale =
      std::fmax(std::fmax(std::fabs(want.x), std::fabs(want.y)), std::fabs(want.z));
  const double tol = eps * (scale > 0 ? scale : 1.0) + 1e-300;
  EXPECT_NEAR(got.x, want.x, tol) << what;
  EXPECT_NEAR(got.y, want.y, tol) << what;
  EXPECT_NEAR(got.z, want.z, tol) << what;
}
} // namespace

TEST(LsdReference, MatchesIndependentPythonImplementation) {
  const YAML::Node doc = YAML::LoadFile(COREDEM_DEM_TEST_DATA "/lsd_contact.yaml");
  const double eps = doc["epsilon"].as<double>();
  ASSERT_GE(doc["cases"].size(), 4u);
  for (const YAML::Node& c : doc["cases"]) {
    const std::string name = c["name"].as<std::string>();
    const Vec3 xi = vec(c["xi"]), xj = vec(c["xj"]);
    const double ri = c["ri"].as<double>(), rj = c["rj"].as<double>(), rho = c["rho"].as<double>();
    const double pi = 3.14159265358979323846;
    const double mi = rho * 4.0 / 3.0 * pi * ri * ri * ri, mj = rho * 4.0 / 3.0 * pi * rj * rj * rj;
    const double kn = c["kn"].as<double>();
    const double etan = normalDamping(kn, effectiveMass(mi, mj), c["en"].as<double>());
    const LsdParams p{kn, 2.0 / 7.0 * kn, etan, 0.5 * etan, c["mu"].as<double>()};
    const Vec3 d = xj - xi;
    const double l = norm(d);
    const Vec3 n = (1.0 / l) * d;
    const double lij = leverArm(l, ri, rj), lji = leverArm(l, rj, ri);
    const Vec3 vij =
        relativeVelocity(vec(c["vi"]), vec(c["vj"]), vec(c["wi"]), vec(c["wj"]), lij, lji, n);
    const LsdResult r =
        lsdContact(p, n, ri + rj - l, vij, lij, vec(c["dt_old"]), c["dt"].as<double>());
    expectVec(r.force, vec(c["force"]), eps, name + " force");
    expectVec(r.torque, vec(c["torque"]), eps, name + " torque");
    expectVec(r.deltaT, vec(c["dt_new"]), eps, name + " dt_new");
  }
}
