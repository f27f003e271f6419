#include "support/chandrasekhar.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace nimbus::test {
namespace chandrasekhar_test {

// The quadrature is accurate to ~1e-13 (two DE levels agree to 1e-12 and it converges
// double-exponentially), so identities are checked to 1e-10; tables have 5 decimals.
constexpr double kIdentityTol = 1e-10;
constexpr double kTableTol = 0.6e-5;

TEST(Chandrasekhar, ConservativeTable) {
  // Chandrasekhar (1950), the tabulated H for conservative isotropic scattering (ω = 1).
  EXPECT_EQ(chandrasekhar_h(0, 1), 1.0);
  EXPECT_NEAR(chandrasekhar_h(0.1, 1), 1.24735, kTableTol);
  EXPECT_NEAR(chandrasekhar_h(0.5, 1), 2.01278, kTableTol);
  EXPECT_NEAR(chandrasekhar_h(1, 1), 2.90781, kTableTol);
}

TEST(Chandrasekhar, IncreasesWithMuAndAlbedo) {
  for (double omega : {0.3, 0.9, 1.0}) {
    double prev = 1;
    for (int i = 1; i <= 20; ++i) {
      const double h = chandrasekhar_h(i / 20.0, omega);
      EXPECT_GT(h, prev) << omega << " " << i;
      prev = h;
    }
  }
  EXPECT_LT(chandrasekhar_h(0.7, 0.8), chandrasekhar_h(0.7, 0.9));
}

TEST(Chandrasekhar, ZerothMoment) {
  // α₀ = ∫_0^1 H dμ = (2/ω)(1 − √(1 − ω)).
  for (double omega : {1.0, 0.99, 0.9, 0.5, 0.1}) {
    const double alpha0 =
        tanh_sinh([&](double mu, double) { return chandrasekhar_h(mu, omega); }, 0, 1, 1e-12);
    EXPECT_NEAR(alpha0, 2 / omega * (1 - std::sqrt(1 - omega)), kIdentityTol) << omega;
  }
}

TEST(Chandrasekhar, FirstMomentConservative) {
  // α₁ = ∫_0^1 μ H dμ = 2/√3 for ω = 1.
  const double alpha1 =
      tanh_sinh([](double mu, double) { return mu * chandrasekhar_h(mu, 1); }, 0, 1, 1e-12);
  EXPECT_NEAR(alpha1, 2 / std::sqrt(3.0), kIdentityTol);
}

TEST(Chandrasekhar, HalfSpaceReflectsItsPlaneAlbedo) {
  // Reflected flux 2π ∫_0^1 L_r(μ) μ dμ over incident flux E μ₀ is the plane albedo
  // 1 − H(μ₀) √(1 − ω) (from H's integral equation): all of it when ω = 1 (energy check).
  const double E = 3.0;
  for (double omega : {1.0, 0.8, 0.3}) {
    for (double mu0 : {0.1, 0.5, 1.0}) {
      const double reflected =
          2 * std::numbers::pi *
          tanh_sinh([&](double mu,
                        double) { return half_space_reflected_radiance(E, omega, mu0, mu) * mu; },
                    0, 1, 1e-12);
      const double albedo = 1 - chandrasekhar_h(mu0, omega) * std::sqrt(1 - omega);
      EXPECT_NEAR(reflected / (E * mu0), albedo, kIdentityTol) << omega << " " << mu0;
      if (omega == 1) {
        EXPECT_NEAR(reflected, E * mu0, kIdentityTol * E);
      }
    }
  }
}

}  // namespace chandrasekhar_test
}  // namespace nimbus::test
