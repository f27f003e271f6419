#include "nimbus/render/microfacet.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "nimbus/math/constants.h"
#include "nimbus/math/rng.h"
#include "nimbus/render/material.h"
#include "nimbus/render/sampling.h"
#include "support/stats.h"

namespace nimbus {
namespace microfacet_test {

constexpr double kDeg = kPi / 180;

Vec3 direction(double theta, double phi, double side) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), side * std::cos(theta)};
}

// wo at theta_deg from the normal on `side`, at an azimuth off the axes.
constexpr double kAzimuth = 0.7;
Vec3 incident(double theta_deg, double side) {
  return direction(theta_deg * kDeg, kAzimuth, side);
}

double wrap_angle(double x) {  // to [−π, π)
  return x - 2 * kPi * std::floor((x + kPi) / (2 * kPi));
}

// x in [lo, hi] as a function of u in [0, 1], dense around c within about w: a Cauchy warp, so
// that a lobe of width ~w spreads over many of the equal steps in u.
struct Warp {
  double c, w, a0, a1;
  Warp(double lo, double hi, double centre, double width)
      : c(centre),
        w(width),
        a0(std::atan((lo - centre) / width)),
        a1(std::atan((hi - centre) / width)) {}
  double x(double u) const { return c + w * std::tan(a0 + u * (a1 - a0)); }
  double dx_du(double u) const {
    const double t = std::tan(a0 + u * (a1 - a0));
    return w * (a1 - a0) * (1 + t * t);
  }
  double u(double x) const { return (std::atan((x - c) / w) - a0) / (a1 - a0); }
};

// Bins of one hemisphere, z of sign `side`: (θ, φ) about ±z, so that the horizon, where the
// pdf jumps from reflection to transmission, is a bin edge, as is θ_edge (where the facets that
// refract wo reach the horizon: there the pdf jumps to 0); warped around a lobe centre.
struct HemisphereBins {
  static constexpr int kTheta = 12, kPhi = 12;
  double side, phi_c;
  std::array<Warp, 2> theta;  // [0, θ_edge], [θ_edge, π/2]
  int inner;                  // bins in [0, θ_edge]
  Warp phi;                   // φ − φ_c in [−π, π)

  HemisphereBins(double side_, double theta_c, double phi_c_, double w_theta, double w_phi,
                 double theta_edge = kPi / 2)
      : side(side_),
        phi_c(phi_c_),
        theta{Warp(0, theta_edge, theta_c, w_theta), Warp(theta_edge, kPi / 2, theta_c, w_theta)},
        inner(theta_edge < kPi / 2
                  ? std::clamp(
                        int(std::lround(kTheta * Warp(0, kPi / 2, theta_c, w_theta).u(theta_edge))),
                        1, kTheta - 1)
                  : kTheta),
        phi(-kPi, kPi, 0, w_phi) {}

  int bin(const Vec3& w) const {
    const double th = std::acos(std::clamp(std::abs(w.z), 0.0, 1.0));
    const double ph = wrap_angle(std::atan2(w.y, w.x) - phi_c);
    const int outer = th < theta[1].x(0) ? 0 : 1;
    const int n = outer ? kTheta - inner : inner;
    const int i = (outer ? inner : 0) + std::clamp(int(theta[outer].u(th) * n), 0, n - 1);
    const int j = std::clamp(static_cast<int>(phi.u(ph) * kPhi), 0, kPhi - 1);
    return i * kPhi + j;
  }
  // ∫ f over each bin (solid angle), adaptively in the warped coordinates (to within about tol
  // over the hemisphere, or `rel` of each bin, up to max_depth halvings of a bin). f must be
  // symmetric about the plane φ = φ_c, as an isotropic BSDF's pdf is about the plane of incidence:
  // the half with φ > φ_c is mirrored.
  std::vector<double> integrate(const std::function<double(const Vec3&)>& f, double tol,
                                double rel = 3e-3, int max_depth = 4) const {
    static_assert(kPhi % 2 == 0);
    std::vector<double> out(kTheta * kPhi);
    for (int i = 0; i < kTheta; ++i) {
      const int outer = i < inner ? 0 : 1;
      const int n = outer ? kTheta - inner : inner, k = outer ? i - inner : i;
      const auto g = [&](double ut, double up) {
        const double u = (k + ut) / n, th = theta[outer].x(u);
        return f(direction(th, phi_c + phi.x(up), side)) * std::sin(th) * theta[outer].dx_du(u) /
               n * phi.dx_du(up);
      };
      for (int j = kPhi / 2; j < kPhi; ++j) {
        const Cell c{0, 1, double(j) / kPhi, double(j + 1) / kPhi};
        out[i * kPhi + j] = out[i * kPhi + kPhi - 1 - j] =
            adaptive(g, c, gauss(g, c), {tol, rel}, max_depth);
      }
    }
    return out;
  }

 private:
  struct Cell {
    double u0, u1, v0, v1;
  };
  struct Tol {
    double abs, rel;  // abs: per unit area of the hemisphere's (u_θ, u_φ) square
  };
  // 3×3 Gauss–Legendre on a cell.
  template <class G>
  static double gauss(const G& g, const Cell& c) {
    static constexpr double x[3] = {0.5 - 0.3872983346207417, 0.5, 0.5 + 0.3872983346207417};
    static constexpr double w[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
    double s = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        s += w[a] * w[b] * g(c.u0 + x[a] * (c.u1 - c.u0), c.v0 + x[b] * (c.v1 - c.v0));
    return s * (c.u1 - c.u0) * (c.v1 - c.v0);
  }
  // A cell's estimate is kept when its quarters agree with it to within tol, or when no more
  // halvings (depth) are allowed.
  template <class G>
  static double adaptive(const G& g, const Cell& c, double whole, Tol tol, int depth) {
    const double um = 0.5 * (c.u0 + c.u1), vm = 0.5 * (c.v0 + c.v1);
    const Cell q[4] = {
        {c.u0, um, c.v0, vm}, {um, c.u1, c.v0, vm}, {c.u0, um, vm, c.v1}, {um, c.u1, vm, c.v1}};
    double part[4], sum = 0;
    for (int k = 0; k < 4; ++k) sum += part[k] = gauss(g, q[k]);
    const double area = (c.u1 - c.u0) * (c.v1 - c.v0);
    if (depth == 0 || std::abs(sum - whole) <= std::max(tol.rel * std::abs(sum), tol.abs * area))
      return sum;
    double refined = 0;
    for (int k = 0; k < 4; ++k) refined += adaptive(g, q[k], part[k], tol, depth - 1);
    return refined;
  }
};

// ---------------------------------------------------------------------------------------------
// The cases of the acceptance criterion: roughness 0.01 to 1, incidence 10°, 45°, 80°, both
// sides, η 1.1 to 2.4.

enum class Kind { Conductor, Dielectric };

struct Case {
  Kind kind;
  double alpha, theta_deg, side, eta;
  Vec3 wo = incident(theta_deg, side);

  std::string name() const {
    return std::string(kind == Kind::Conductor ? "conductor" : "dielectric") +
           " alpha=" + std::to_string(alpha) + " theta=" + std::to_string(theta_deg) +
           " side=" + std::to_string(side) + " eta=" + std::to_string(eta);
  }
  double pdf(const Vec3& wi) const {
    return kind == Kind::Conductor ? conductor_microfacet_pdf(alpha, wo, wi)
                                   : dielectric_microfacet_pdf(alpha, eta, wo, wi);
  }
  double f(const Vec3& wi) const {
    return kind == Kind::Conductor ? conductor_microfacet(alpha, wo, wi)
                                   : dielectric_microfacet(alpha, eta, wo, wi);
  }
  MicrofacetSample sample(Rng& rng) const {
    const double uc = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    return kind == Kind::Conductor ? sample_conductor_microfacet(alpha, wo, u1, u2)
                                   : sample_dielectric_microfacet(alpha, eta, wo, uc, u1, u2);
  }
};

std::vector<Case> acceptance_cases() {
  std::vector<Case> cases;
  for (double alpha : {0.01, 0.05, 0.2, 0.5, 1.0})
    for (double theta : {10.0, 45.0, 80.0})
      for (double side : {1.0, -1.0}) {
        cases.push_back({Kind::Conductor, alpha, theta, side, 0});
        for (double eta : {1.1, 1.5, 2.4})
          cases.push_back({Kind::Dielectric, alpha, theta, side, eta});
      }
  return cases;
}

// The direction a facet wm (on wo's side) sends wo to, by the mirror law or Snell's law (ratio
// e across the facet); false when there is none on the hemisphere asked for.
bool scatter(const Vec3& wo, const Vec3& wm, bool refract, double e, Vec3& wi) {
  const double c = dot(wo, wm);
  if (!refract) {
    wi = wm * (2 * c) - wo;
    return wi.z * wo.z > 0;
  }
  const double s2 = (1 - c * c) / (e * e);
  if (s2 >= 1) return false;
  wi = -wo / e + wm * (c / e - std::sqrt(1 - s2));
  return wi.z * wo.z < 0;
}

// Bins for the hemisphere of wi on wo's side (reflection) or the other: centred on where the
// macro normal sends wo, widths from where facets tilted by atan α send it.
HemisphereBins bins_for(const Case& cs, bool transmission) {
  const Vec3 wo = cs.wo;
  const double sign = wo.z > 0 ? 1.0 : -1.0;
  const double side = transmission ? -sign : sign;
  const double phi_o = std::atan2(wo.y, wo.x);
  if (transmission && cs.kind == Kind::Conductor) return {side, kPi / 2, phi_o + kPi, 1, 2};
  const double e = cs.kind == Kind::Conductor ? 1.0 : wo.z > 0 ? cs.eta : 1 / cs.eta;
  const Vec3 n{0, 0, sign};
  Vec3 wi;
  // Facets at the horizon, (wo + e wi).z = 0, refract wo to |wi.z| = |wo.z|/e.
  const double edge = transmission && std::abs(wo.z) < e ? std::acos(std::abs(wo.z) / e) : kPi / 2;
  if (!scatter(wo, n, transmission, e, wi)) return {side, kPi / 2, phi_o + kPi, 1, 2, edge};
  const double theta_c = std::acos(std::abs(wi.z)), phi_c = phi_o + kPi;
  const Vec3 along{std::cos(phi_o), std::sin(phi_o), 0}, across{-along.y, along.x, 0};
  // A tilted facet that sends wo nowhere on this hemisphere: the lobe is as wide as it.
  double w_theta = 1e-4, w_phi = 1e-4;
  for (const Vec3& t : {along, along * -1.0, across, across * -1.0}) {
    const Vec3 wm = normalize(n + t * cs.alpha);
    if (dot(wo, wm) <= 0 || !scatter(wo, wm, transmission, e, wi)) {
      w_theta = std::max(w_theta, 1.0);
      w_phi = std::max(w_phi, 2.0);
      continue;
    }
    w_theta = std::max(w_theta, std::abs(std::acos(std::abs(wi.z)) - theta_c));
    w_phi = std::max(w_phi, std::abs(wrap_angle(std::atan2(wi.y, wi.x) - phi_c)));
  }
  // Refraction compresses the facets' spread by about |1 − 1/e| (a thin prism), which matters
  // where η is near 1 and the lobe is broad.
  if (transmission) {
    const double squeeze = std::max(0.05, 2 * std::abs(1 - 1 / e));
    w_theta = std::min(w_theta, squeeze);
    w_phi = std::min(w_phi, 2 * squeeze);
  }
  return {side, theta_c, phi_c, w_theta, w_phi, edge};
}

// Upper-tail probability of χ² with k degrees of freedom (Wilson & Hilferty 1931, as
// test::chi_square_critical).
double chi_square_p(double chi2, int k) {
  const double v = 2.0 / (9.0 * k);
  const double z = (std::cbrt(chi2 / k) - (1 - v)) / std::sqrt(v);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

struct ChiSquare {
  double chi2 = 0, p = 1, mass = 0;  // mass: ∫ pdf over the sphere
  int dof = 0;
  int64_t discarded = 0;
};

// Sampled directions against the pdf over the whole sphere: both hemispheres' bins and one
// for discarded samples, expected 1 − ∫ pdf. Bins expected below 5 are pooled.
ChiSquare chi_square(const Case& cs, int samples, uint64_t stream) {
  const std::array<HemisphereBins, 2> hemis{bins_for(cs, false), bins_for(cs, true)};
  const int per = HemisphereBins::kTheta * HemisphereBins::kPhi;
  std::vector<double> expected;
  for (const auto& h : hemis)
    for (double p : h.integrate([&](const Vec3& wi) { return cs.pdf(wi); }, 3e-5))
      expected.push_back(p);
  ChiSquare out;
  for (double p : expected) out.mass += p;
  std::vector<int64_t> observed(expected.size() + 1, 0);
  Rng rng(42, stream);
  const Vec3 wo = cs.wo;
  for (int n = 0; n < samples; ++n) {
    const MicrofacetSample s = cs.sample(rng);
    if (s.pdf == 0) {
      ++observed.back();
      continue;
    }
    const int h = s.wi.z * wo.z > 0 ? 0 : 1;
    ++observed[h * per + hemis[h].bin(s.wi)];
  }
  out.discarded = observed.back();
  for (double& e : expected) e *= samples;
  expected.push_back(std::max(0.0, 1 - out.mass) * samples);
  constexpr double kMinExpected = 5;
  double pool_e = 0, pool_o = 0;
  int bins = 0;
  for (size_t b = 0; b < expected.size(); ++b) {
    if (expected[b] < kMinExpected) {
      pool_e += expected[b];
      pool_o += double(observed[b]);
      continue;
    }
    const double d = double(observed[b]) - expected[b];
    out.chi2 += d * d / expected[b];
    ++bins;
  }
  // A pool still below the threshold, but holding samples, is a bin of its own: samples where
  // the pdf says almost none must show.
  if (pool_e >= kMinExpected || pool_o > 0) {
    const double e = std::max(pool_e, 1e-3);
    out.chi2 += (pool_o - e) * (pool_o - e) / e;
    ++bins;
  }
  out.dof = bins - 1;
  out.p = chi_square_p(out.chi2, out.dof);
  return out;
}

// ---------------------------------------------------------------------------------------------

double integral(const HemisphereBins& bins, const std::function<double(const Vec3&)>& f, double tol,
                double rel, int depth) {
  double total = 0;
  for (double v : bins.integrate(f, tol, rel, depth)) total += v;
  return total;
}

TEST(MicrofacetDistribution, NormalisedAndSmithConsistent) {
  // ∫ D(wm) wm.z dwm = 1 over the upper hemisphere, and ∫ D_wo(wm) dwm = 1 for wo on either
  // side: G1 = 1/(1 + Λ) is what normalises the visible normals (Heitz 2014), so this checks Λ.
  // Bins warped around the pole with width α; the quadrature is good to 4e-6 (the kink of
  // D_wo at wo·wm = 0 crosses the bins).
  for (double alpha : {0.01, 0.05, 0.2, 0.5, 1.0}) {
    const HemisphereBins up(1, 0, kAzimuth, alpha, 4), down(-1, 0, kAzimuth, alpha, 4);
    const auto projected = [&](const Vec3& m) { return ggx_d(alpha, m) * m.z; };
    EXPECT_NEAR(integral(up, projected, 1e-6, 1e-5, 4), 1, 1e-6) << "alpha " << alpha;
    for (double theta : {0.0, 10.0, 45.0, 80.0, 89.9})
      for (double side : {1.0, -1.0}) {
        const Vec3 wo = incident(theta, side);
        const auto visible = [&](const Vec3& m) { return visible_normal_pdf(alpha, wo, m); };
        EXPECT_NEAR(integral(side > 0 ? up : down, visible, 1e-6, 1e-5, 4), 1, 2e-5)
            << "alpha " << alpha << " theta " << theta << " side " << side;
      }
  }
}

TEST(MicrofacetDistribution, SmithTermsAtKnownPoints) {
  // Λ = (√(1 + α² tan²θ) − 1)/2: 0 at normal incidence, (√2 − 1)/2 at α tan θ = 1; G1 → 0 at
  // grazing; G ≤ min(G1(wo), G1(wi)).
  EXPECT_EQ(smith_lambda(0.5, {0, 0, 1}), 0);
  EXPECT_EQ(smith_lambda(0.5, {0, 0, -1}), 0);
  const Vec3 w45 = incident(45, 1);
  EXPECT_NEAR(smith_lambda(1, w45), (std::sqrt(2.0) - 1) / 2, 1e-15);
  EXPECT_NEAR(smith_lambda(1, incident(45, -1)), (std::sqrt(2.0) - 1) / 2, 1e-15);
  EXPECT_EQ(smith_g1(0.3, {1, 0, 0}), 0);
  EXPECT_NEAR(ggx_d(0.5, {0, 0, 1}), 1 / (kPi * 0.25), 1e-15);
  const Vec3 w80 = incident(80, 1);
  EXPECT_LT(smith_g(0.5, w45, w80), std::min(smith_g1(0.5, w45), smith_g1(0.5, w80)));
}

// ---------------------------------------------------------------------------------------------

// An independent reference: the amplitude coefficients in complex arithmetic, with
// cos θ_t = √(1 − sin²θ/η̃²) taken with Im ≥ 0 (the wave decays into the metal).
double fresnel_complex_reference(double c, double eta, double k) {
  using C = std::complex<double>;
  const C n(eta, k);
  C ct = std::sqrt(1.0 - (1 - c * c) / (n * n));
  if (ct.imag() < 0) ct = -ct;
  const C rs = (c - n * ct) / (c + n * ct), rp = (n * c - ct) / (n * c + ct);
  return 0.5 * (std::norm(rs) + std::norm(rp));
}

TEST(MicrofacetFresnel, ConductorWithoutAbsorptionIsTheDielectric) {
  // k = 0 on both sides of 1, with total internal reflection for η < 1.
  for (double eta : {0.4, 0.8, 1.1, 1.5, 2.4})
    for (int i = 0; i <= 100; ++i) {
      // Off the critical angle, where F has an infinite slope and both round differently.
      const double c = (i + 0.5) / 101;
      EXPECT_NEAR(fresnel_conductor(c, eta, 0), fresnel_dielectric(c, eta), 1e-13)
          << "eta " << eta << " cos " << c;
    }
}

TEST(MicrofacetFresnel, ConductorAtNormalIncidenceAndAgainstComplexArithmetic) {
  struct Index {
    double eta, k;
  };
  // Metal-like (gold, silver, aluminium in the visible), lossy dielectric-like, strong k.
  for (const Index& n : {Index{0.18, 3.4}, Index{0.05, 4.2}, Index{1.2, 7.3}, Index{1.5, 0.01},
                         Index{2.9, 3.0}, Index{0.6, 0.3}}) {
    const double normal =
        ((n.eta - 1) * (n.eta - 1) + n.k * n.k) / ((n.eta + 1) * (n.eta + 1) + n.k * n.k);
    EXPECT_NEAR(fresnel_conductor(1, n.eta, n.k), normal, 1e-15) << n.eta << " " << n.k;
    for (int i = 0; i <= 50; ++i) {
      const double c = i / 50.0, F = fresnel_conductor(c, n.eta, n.k);
      EXPECT_NEAR(F, fresnel_complex_reference(c, n.eta, n.k), 1e-13) << n.eta << " " << c;
      EXPECT_TRUE(F >= 0 && F <= 1);
    }
    EXPECT_NEAR(fresnel_conductor(0, n.eta, n.k), 1, 1e-15);  // grazing
  }
}

TEST(MicrofacetFresnel, LosslessMetalsReflectEverything) {
  // η = 0: a purely imaginary index reflects all (|r| = 1 exactly); k → ∞ likewise in the limit.
  for (int i = 0; i <= 20; ++i) {
    const double c = i / 20.0;
    for (double k : {0.5, 3.0, 50.0}) EXPECT_NEAR(fresnel_conductor(c, 0, k), 1, 1e-14) << c;
    for (double eta : {0.2, 1.0, 3.0}) EXPECT_GT(fresnel_conductor(c, eta, 1e8), 1 - 1e-7) << c;
  }
}

// ---------------------------------------------------------------------------------------------

std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

constexpr int kChiSquareSamples = 10000;

// One chi-square per acceptance case, computed once for the tests below.
const std::vector<ChiSquare>& chi_squares() {
  static const std::vector<ChiSquare> results = [] {
    std::vector<ChiSquare> r;
    const std::vector<Case> cases = acceptance_cases();
    for (size_t i = 0; i < cases.size(); ++i)
      r.push_back(chi_square(cases[i], kChiSquareSamples, i));
    return r;
  }();
  return results;
}

TEST(MicrofacetSampling, ChiSquareOverTheSphere) {
  // Every case's sampled directions against its pdf, integrated over bins of the whole sphere
  // (reflection and transmission hemispheres) plus a bin for discarded samples. Bins follow the
  // lobe (bins_for), so that at α = 0.01 it still fills over a hundred bins. Significance 1e-4
  // for the whole test, Šidák-corrected over the cases. (With 400 000 samples, 40 times these,
  // the cases with the lowest p here give p from 0.29 to 0.99.)
  const std::vector<Case> cases = acceptance_cases();
  const double alpha_case = -std::expm1(std::log1p(-1e-4) / double(cases.size()));
  double worst_p = 1;
  int fewest_dof = 1 << 30;
  for (size_t i = 0; i < cases.size(); ++i) {
    const ChiSquare& r = chi_squares()[i];
    worst_p = std::min(worst_p, r.p);
    fewest_dof = std::min(fewest_dof, r.dof);
    EXPECT_LT(r.chi2, test::chi_square_critical(r.dof, alpha_case))
        << cases[i].name() << ": chi2 " << r.chi2 << ", dof " << r.dof << ", p " << r.p;
    EXPECT_GE(r.dof, 25) << cases[i].name() << ": too few bins to test the lobe's shape";
  }
  RecordProperty("cases", int(cases.size()));
  RecordProperty("worst_p", sci(worst_p));
  RecordProperty("fewest_dof", fewest_dof);
}

TEST(MicrofacetSampling, PdfIntegratesToTheKeptFraction) {
  // ∫ pdf over the sphere is at most 1, and equals the fraction of samples kept: 1 where none
  // is discarded (the bins' quadrature is good to ~4e-4 over a hemisphere, at worst).
  const std::vector<Case> cases = acceptance_cases();
  int none_discarded = 0;
  for (size_t i = 0; i < cases.size(); ++i) {
    const ChiSquare& r = chi_squares()[i];
    const double kept = 1 - double(r.discarded) / kChiSquareSamples;
    EXPECT_LE(r.mass, 1 + 1e-3) << cases[i].name();
    EXPECT_NEAR(r.mass, kept, 4 * std::sqrt(kept * (1 - kept) / kChiSquareSamples) + 1e-3)
        << cases[i].name();
    if (r.discarded == 0) {
      ++none_discarded;
      EXPECT_NEAR(r.mass, 1, 1e-3) << cases[i].name();
    }
  }
  EXPECT_GE(none_discarded, 5);
}

// The ratio of two quantities that should agree, as a relative error; 0 when both are 0.
double relative_error(double a, double b) {
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale > 0 ? std::abs(a - b) / scale : 0.0;
}

TEST(MicrofacetSampling, WeightAndPdfMatchEvaluation) {
  // A kept sample's pdf is what the pdf function gives for its direction, its weight f·|wi.z|/pdf
  // from the evaluation functions, and `reflected` says which side wi is on. Both recompute the
  // facet normal from (wo, wi); at α = 0.01 a rounding of wm moves D by up to ~4/α ulps.
  double worst_pdf = 0, worst_weight = 0;
  int kept = 0;
  for (const Case& cs : acceptance_cases()) {
    Rng rng(7, uint64_t(cs.alpha * 1000 + cs.theta_deg + 10 * cs.eta + (cs.side > 0)));
    for (int n = 0; n < 2000; ++n) {
      const MicrofacetSample s = cs.sample(rng);
      ASSERT_TRUE(std::isfinite(s.pdf) && std::isfinite(s.weight)) << cs.name();
      if (s.pdf == 0) {
        EXPECT_EQ(s.weight, 0) << cs.name();
        continue;
      }
      ++kept;
      const double pdf = cs.pdf(s.wi), f = cs.f(s.wi);
      ASSERT_GT(pdf, 0) << cs.name();
      worst_pdf = std::max(worst_pdf, relative_error(s.pdf, pdf));
      worst_weight = std::max(worst_weight, relative_error(s.weight, f * std::abs(s.wi.z) / pdf));
      EXPECT_EQ(s.reflected, s.wi.z * cs.wo.z > 0) << cs.name();
      EXPECT_TRUE(s.weight > 0 && s.weight <= 1) << cs.name() << ": " << s.weight;
      EXPECT_NEAR(length(s.wi), 1, 1e-12) << cs.name();
    }
  }
  EXPECT_GT(kept, 200000);
  EXPECT_LT(worst_pdf, 1e-9);
  EXPECT_LT(worst_weight, 1e-9);
  RecordProperty("worst_pdf_error", sci(worst_pdf));
  RecordProperty("worst_weight_error", sci(worst_weight));
}

TEST(MicrofacetReciprocity, ConductorAndDielectric) {
  // Pairs where the BSDF matters (wi sampled from wo) and uniform ones: the conductor and the
  // dielectric's reflection are symmetric; its transmission obeys
  // f(wo, wi)/n(wi)² = f(wi, wo)/n(wo)² (outside n = 1, inside n = η).
  int transmitted = 0;
  double worst = 0;
  for (const Case& cs : acceptance_cases()) {
    Rng rng(11, uint64_t(cs.alpha * 1000 + cs.theta_deg + 10 * cs.eta + (cs.side > 0)));
    for (int n = 0; n < 400; ++n) {
      const MicrofacetSample s = cs.sample(rng);
      Vec3 wo = cs.wo, wi = s.wi;
      if (n % 2) {
        wo = sample_uniform_sphere(rng.uniform(), rng.uniform());
        wi = sample_uniform_sphere(rng.uniform(), rng.uniform());
      } else if (s.pdf == 0) {
        continue;
      }
      if (cs.kind == Kind::Conductor) {
        worst = std::max(worst, relative_error(conductor_microfacet(cs.alpha, wo, wi),
                                               conductor_microfacet(cs.alpha, wi, wo)));
        continue;
      }
      // Near the refraction cut-offs, where wo·wm or wi·wm → 0 and f with it, each direction
      // computes those cosines with a cancellation: uniform pairs there are left out.
      const double e = wo.z > 0 ? cs.eta : 1 / cs.eta;
      if (wo.z * wi.z < 0 &&
          (std::abs(1 + e * dot(wo, wi)) < 1e-2 || std::abs(e + dot(wo, wi)) < 1e-2))
        continue;
      const auto n2 = [&](const Vec3& w) { return w.z > 0 ? 1.0 : cs.eta * cs.eta; };
      const double forward = dielectric_microfacet(cs.alpha, cs.eta, wo, wi) / n2(wi);
      const double backward = dielectric_microfacet(cs.alpha, cs.eta, wi, wo) / n2(wo);
      transmitted += wo.z * wi.z < 0 && forward > 0;
      worst = std::max(worst, relative_error(forward, backward));
    }
  }
  EXPECT_GT(transmitted, 5000);
  EXPECT_LT(worst, 1e-9);
  RecordProperty("worst_reciprocity_error", sci(worst));
}

TEST(MicrofacetSampling, RefractionCannotBendBackwards) {
  // Entering a denser medium, wi beyond the plane that holds wo and the normal (on wo's side of
  // it) needs a facet facing away from wo: f and pdf are 0 (Walter et al. 2007's half-vector
  // test), and so is wi = −wo at η = 1, where no facet exists.
  const Vec3 wo = incident(60, 1);
  const Vec3 back{wo.x, wo.y, -wo.z};
  EXPECT_EQ(dielectric_microfacet(0.5, 1.5, wo, back), 0);
  EXPECT_EQ(dielectric_microfacet_pdf(0.5, 1.5, wo, back), 0);
  EXPECT_EQ(dielectric_microfacet(0.5, 1.0, wo, -wo), 0);
  EXPECT_EQ(dielectric_microfacet_pdf(0.5, 1.0, wo, -wo), 0);
  // Straight through is possible (the facet facing wo), the mirror image behind is not.
  EXPECT_GT(dielectric_microfacet(0.5, 1.5, wo, -wo), 0);
  EXPECT_EQ(conductor_microfacet(0.5, wo, -wo), 0);
  EXPECT_EQ(conductor_microfacet_pdf(0.5, wo, back), 0);
}

TEST(MicrofacetDielectric, TinyRoughnessIsTheSmoothDielectric) {
  // α below the clamp samples what render/material.h's smooth dielectric does with the same
  // number, from either side, with weight 1: the conventions (η's direction, wo's) agree. GGX's
  // tail (tilts beyond t have probability ~α²/t²) lets a few directions stray further.
  Rng rng(5);
  int compared = 0, close = 0;
  for (double theta : {0.0, 20.0, 45.0, 70.0})
    for (double side : {1.0, -1.0})
      for (double eta : {1.1, 1.5, 2.4}) {
        const Vec3 wo = incident(theta, side);
        for (int n = 0; n < 50; ++n) {
          const double uc = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
          const MicrofacetSample s = sample_dielectric_microfacet(1e-7, eta, wo, uc, u1, u2);
          const DielectricSample smooth = sample_dielectric(wo, {0, 0, 1}, eta, uc);
          if (std::abs(uc - smooth.F) < 1e-3) continue;  // F moved with the facet
          ASSERT_GT(s.pdf, 0);
          EXPECT_EQ(s.reflected, smooth.reflected) << theta << " " << side << " " << eta;
          EXPECT_LT(length(s.wi - smooth.wi), 0.05) << theta << " " << side << " " << eta;
          EXPECT_GT(s.weight, 1 - 1e-6);
          ++compared;
          close += length(s.wi - smooth.wi) < 1e-3;
        }
      }
  EXPECT_GT(close, 0.95 * compared);
}

TEST(MicrofacetDegenerate, FiniteForGrazingAndExtremeInputs) {
  // Horizon and near-horizon directions, normal incidence (no azimuth to stretch along), α = 0,
  // the edges of the unit square, η = 1: nothing is NaN or infinite, pdfs and f are ≥ 0, kept
  // samples have weights in [0, 1].
  const std::vector<Vec3> dirs{{0, 0, 1},
                               {0, 0, -1},
                               {1, 0, 0},
                               {0.6, 0.8, 0},
                               incident(89.9999999, 1),
                               incident(89.9999999, -1),
                               {1, 0, 1e-160},
                               {1, 0, -1e-300},
                               incident(45, 1)};
  const double u_max = std::nextafter(1.0, 0.0);
  for (double alpha : {0.0, 1e-9, 0.01, 1.0})
    for (double eta : {1.0, 1.5, 1 / 1.5})
      for (const Vec3& wo : dirs) {
        for (const Vec3& wi : dirs)
          for (const double v :
               {ggx_d(alpha, wi), smith_g(alpha, wo, wi), conductor_microfacet(alpha, wo, wi),
                conductor_microfacet_pdf(alpha, wo, wi), dielectric_microfacet(alpha, eta, wo, wi),
                dielectric_microfacet_pdf(alpha, eta, wo, wi)})
            EXPECT_TRUE(std::isfinite(v) && v >= 0) << alpha << " " << eta;
        for (double u1 : {0.0, 0.5, u_max})
          for (double u2 : {0.0, 0.25, u_max})
            for (double uc : {0.0, u_max}) {
              const Vec3 wm = sample_visible_normal(alpha, wo, u1, u2);
              EXPECT_TRUE(std::isfinite(wm.x + wm.y + wm.z));
              for (const MicrofacetSample& s :
                   {sample_conductor_microfacet(alpha, wo, u1, u2),
                    sample_dielectric_microfacet(alpha, eta, wo, uc, u1, u2)}) {
                EXPECT_TRUE(std::isfinite(s.pdf) && s.pdf >= 0);
                EXPECT_TRUE(s.weight >= 0 && s.weight <= 1);
                EXPECT_TRUE(std::isfinite(s.wi.x + s.wi.y + s.wi.z));
              }
            }
      }
}

TEST(MicrofacetConductor, SingleScatteringAlbedoOfAPerfectMirrorMetal) {
  // Directional albedo ∫ f |wi.z| dwi of the F = 1 conductor: by quadrature of f and by the
  // mean of sampled weights. Single scattering loses what leaves after more than one bounce on
  // the facets: at α = 1 and 45°, 62% of the energy (the number for the compensation work; a
  // separate 400 × 400 midpoint quadrature of Walter's formulas gives 0.376775).
  const auto albedo = [](double alpha, const Vec3& wo) {
    const HemisphereBins bins(1, 0, kAzimuth + kPi, 1, 2);
    return integral(
        bins, [&](const Vec3& wi) { return conductor_microfacet(alpha, wo, wi) * wi.z; }, 1e-7,
        1e-6, 4);
  };
  const Vec3 wo = incident(45, 1);
  const double quadrature = albedo(1, wo);
  test::MeanVar mc;
  Rng rng(3);
  for (int n = 0; n < 20000; ++n)
    mc.add(sample_conductor_microfacet(1, wo, rng.uniform(), rng.uniform()).weight);
  EXPECT_NEAR(mc.mean, quadrature, 4 * mc.std_error());
  EXPECT_NEAR(quadrature, 0.37678, 2e-5);
  RecordProperty("albedo_alpha1_45deg", sci(quadrature));
  // Smoother surfaces lose less, down to nothing.
  EXPECT_LT(quadrature, albedo(0.5, wo));
  EXPECT_LT(albedo(0.5, wo), albedo(0.2, wo));
  EXPECT_GT(albedo(0.05, wo), 0.99);
}

}  // namespace microfacet_test
}  // namespace nimbus
