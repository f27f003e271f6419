// The weighted trackers of tracking/ in isolation (issue 5): spectral tracking with the channel,
// max (eq. 6–9) and history (eq. 10–13) rules, with and without absorption events, decomposition
// tracking, and the hero tracking of spectral MIS, against analytic 1D media whose extinction
// differs per channel.
//
// For a segment [kT0, kT1] with transmittance T and constant albedo α per channel, a walk that
// starts with weight 1 and emission L_e = 1 has
//   E[w ; escape]   = T
//   E[w ; scatter]  = α (1 − T)        (∫ T(t) mu_s(t) dt)
//   E[emitted]      = (1 − α)(1 − T)   (∫ T(t) mu_a(t) L_e dt)

#include "nimbus/tracking/spectral_tracking.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "nimbus/math/rng.h"
#include "nimbus/tracking/decomposition_tracking.h"
#include "nimbus/tracking/spectral_mis.h"
#include "support/contribution_weight.h"
#include "support/stats.h"

namespace nimbus {
namespace spectral_tracking_test {

constexpr double kT0 = 0.2, kT1 = 1.4;
const Rgb kAlbedo{{0.95, 0.5, 0.8}};
constexpr int kWalks = 100000;

// mu_t(t) = A sin²(k t) + base per channel, uncorrelated between channels.
struct Profile {
  Rgb A{{3.0, 1.0, 4.0}}, k{{3.0, 7.0, 1.5}}, base{{0.4, 1.2, 0.3}};
  double density = 1;  // multiplies mu_t: a "wrong" density tests that the checks can fail

  Rgb mu_t(double t) const {
    Rgb m;
    for (int i = 0; i < 3; ++i) m[i] = density * (A[i] * std::pow(std::sin(k[i] * t), 2) + base[i]);
    return m;
  }
  MediumSample<3> at(double t) const {
    const Rgb m = mu_t(t);
    return {m * (Rgb(1.0) - kAlbedo), m * kAlbedo, Rgb(1.0)};
  }
  // The exact transmittance of the unscaled medium.
  Rgb transmittance() const {
    Rgb T;
    for (int i = 0; i < 3; ++i) {
      auto F = [&](double t) {
        return A[i] * (0.5 * t - std::sin(2 * k[i] * t) / (4 * k[i])) + base[i] * t;
      };
      T[i] = std::exp(-(F(kT1) - F(kT0)));
    }
    return T;
  }
  Rgb majorant() const { return A + base; }       // per channel
  double minorant() const { return base.min(); }  // achromatic
};

// Accumulates the three expectations above per channel.
struct Moments {
  std::array<test::MeanVar, 3> escape, scatter, emitted;
  void add(const Collision& c, const Rgb& w, const Rgb& e) {
    for (int i = 0; i < 3; ++i) {
      escape[i].add(c.event == CollisionEvent::Escape ? w[i] : 0.0);
      scatter[i].add(c.event == CollisionEvent::Scatter ? w[i] : 0.0);
      emitted[i].add(e[i]);
    }
  }
  // The largest |mean − ref| / SE over channels and the three moments.
  double max_z(const Rgb& T) const {
    double z = 0;
    for (int i = 0; i < 3; ++i) {
      const double refs[3] = {T[i], kAlbedo[i] * (1 - T[i]), (1 - kAlbedo[i]) * (1 - T[i])};
      const test::MeanVar* mv[3] = {&escape[i], &scatter[i], &emitted[i]};
      for (int j = 0; j < 3; ++j) {
        const double se = mv[j]->std_error(), err = std::abs(mv[j]->mean - refs[j]);
        z = std::max(z, se > 0 ? err / se : (err < 1e-12 ? 0.0 : 1e9));
      }
    }
    return z;
  }
};

struct Case {
  EventRule rule;
  bool absorption_events;
  bool decomposition;
  double scale;  // of the majorant; 0.5 does not bound
};

std::string case_name(const testing::TestParamInfo<Case>& info) {
  const Case& c = info.param;
  const char* rule = c.rule == EventRule::Channel ? "Channel"
                     : c.rule == EventRule::Max   ? "Max"
                                                  : "History";
  return std::string(rule) + (c.absorption_events ? "Collide" : "Weight") +
         (c.decomposition ? "Decomposition" : "") + (c.scale < 1 ? "Unbounded" : "");
}

Moments run(const Case& c, const Profile& p, uint64_t seed, TrackingCounters& counters) {
  Rng rng(seed);
  EventPolicy policy{c.rule, 0, c.absorption_events};
  auto lookup = [&](double t) { return p.at(t); };
  Moments mom;
  // The channel rule (delta tracking with weights) with a majorant that does not bound carries
  // the excess in one channel, whose weights grow like ±((2 mu_t − mu_bar)/mu_bar)^k: at kWalks
  // the 10 % denser medium stood only 2.9–3.5 standard errors off, so it gets 4 times as many.
  const int walks = c.rule == EventRule::Channel && c.scale < 1 ? 4 * kWalks : kWalks;
  for (int i = 0; i < walks; ++i) {
    policy.channel = i % 3;
    // The channel rule is delta tracking: its majorant is the tracked channel's.
    const double mu_bar = c.scale * (c.rule == EventRule::Channel ? p.majorant()[policy.channel]
                                                                  : p.majorant().max());
    // Delta tracking carries the tracked channel alone, weighted by the 3 channels it stands for.
    Rgb w(1.0), emitted(0.0);
    if (c.rule == EventRule::Channel) {
      w = Rgb(0.0);
      w[policy.channel] = 3;
    }
    const Collision col =
        c.decomposition
            ? decomposition_tracking<3>(lookup, kT0, kT1, p.minorant(), mu_bar, policy, w, emitted,
                                        rng, counters)
            : spectral_tracking<3>(lookup, kT0, kT1, mu_bar, policy, w, emitted, rng, counters);
    mom.add(col, w, emitted);
  }
  return mom;
}

class WeightedTracking : public testing::TestWithParam<Case> {};

TEST_P(WeightedTracking, EscapeScatterAndEmissionAreUnbiased) {
  const Profile p;
  TrackingCounters counters;
  const Moments mom = run(GetParam(), p, 7, counters);
  EXPECT_LT(mom.max_z(p.transmittance()), 4);
  EXPECT_EQ(counters.clamped, 0u);
}

TEST_P(WeightedTracking, DetectsATenPercentDenserMedium) {
  const Case& c = GetParam();
  Profile p;
  p.density = 1.1;
  TrackingCounters counters;
  EXPECT_GT(run(c, p, 8, counters).max_z(Profile{}.transmittance()), 4);
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (EventRule rule : {EventRule::Channel, EventRule::Max, EventRule::History})
    for (bool collide : {true, false})
      for (bool decomposition : {false, true})
        for (double scale : {1.0, 0.5}) out.push_back({rule, collide, decomposition, scale});
  return out;
}

INSTANTIATE_TEST_SUITE_P(Rules, WeightedTracking, testing::ValuesIn(cases()), case_name);

TEST(DecompositionTracking, ZeroControlIsSpectralTracking) {
  const Profile p;
  auto lookup = [&](double t) { return p.at(t); };
  const EventPolicy policy{EventRule::History, 0, false};
  Rng a(9), b(9);
  TrackingCounters ca, cb;
  for (int i = 0; i < 1000; ++i) {
    Rgb wa(1.0), wb(1.0), ea(0.0), eb(0.0);
    const Collision x =
        decomposition_tracking<3>(lookup, kT0, kT1, 0.0, p.majorant().max(), policy, wa, ea, a, ca);
    const Collision y =
        spectral_tracking<3>(lookup, kT0, kT1, p.majorant().max(), policy, wb, eb, b, cb);
    ASSERT_EQ(x.event, y.event);
    ASSERT_EQ(x.t, y.t);
    ASSERT_EQ(wa, wb);
    ASSERT_EQ(ea, eb);
  }
  EXPECT_EQ(ca.lookups, cb.lookups);
}

TEST(DecompositionTracking, ControlCollisionsNeedNoNullLookups) {
  // A homogeneous achromatic-extinction medium is all control (mu_c = mu_bar): each walk looks
  // the density up once, at its real collision; spectral tracking with a loose majorant also
  // looks up at every null collision.
  Profile p;
  p.A = Rgb(0.0);
  p.base = Rgb(2.0);
  auto lookup = [&](double t) { return p.at(t); };
  const EventPolicy policy{EventRule::Max, 0, true};
  Rng rng(10);
  TrackingCounters dec, plain;
  int real = 0;
  for (int i = 0; i < 1000; ++i) {
    Rgb w(1.0), e(0.0);
    real += decomposition_tracking<3>(lookup, kT0, kT1, 2.0, 2.0, policy, w, e, rng, dec).event !=
            CollisionEvent::Escape;
    w = Rgb(1.0);
    spectral_tracking<3>(lookup, kT0, kT1, 3.0, policy, w, e, rng, plain);
  }
  EXPECT_EQ(dec.lookups, uint64_t(real));
  EXPECT_GT(plain.lookups, dec.lookups + 200);
}

TEST(WeightedCollision, HistoryRuleIgnoresDeadChannels) {
  // A channel whose weight is 0 does not pull probability towards its events (eq. 10–13).
  MediumSample<3> m{Rgb({0.0, 0.0, 0.0}), Rgb({0.0, 0.0, 5.0}), Rgb(0.0)};
  const Rgb mu_n({5.0, 5.0, 0.0});
  Rgb w({1.0, 1.0, 0.0}), e(0.0);
  const EventPolicy policy{EventRule::History, 0, true};
  for (double u : {0.0, 0.5, 0.999}) {
    Rgb wu = w;
    EXPECT_EQ(weighted_collision(m, mu_n, 5.0, policy, wu, e, u), TentativeEvent::Null);
    EXPECT_EQ(wu, w);  // P_n = 1 and mu_n/mu_bar = 1 on the live channels
  }
}

// u·c rounds up to c when c is subnormal: the event drawn must still have a positive
// probability, or the weight becomes mu_n · c/(mu_bar · 0) = 0 · ∞ (issue 17).
TEST(WeightedCollision, NeverTakesAnEventOfProbabilityZero) {
  const double tiny = std::numeric_limits<double>::denorm_min();
  const double u = std::nextafter(1.0, 0.0);
  ASSERT_EQ(u * tiny, tiny) << "the rounding this test is about";
  for (EventRule rule : {EventRule::Channel, EventRule::Max, EventRule::History})
    for (bool absorb : {true, false}) {
      const MediumSample<3> m{Rgb(absorb ? tiny : 0.0), Rgb(absorb ? 0.0 : tiny), Rgb(0.0)};
      Rgb w(1.0), e(0.0);
      const TentativeEvent ev =
          weighted_collision(m, Rgb(0.0), 1.0, EventPolicy{rule, 0, true}, w, e, u);
      EXPECT_EQ(ev, absorb ? TentativeEvent::Absorb : TentativeEvent::Scatter);
      for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(w[c]) && std::isfinite(e[c])) << c;
    }
}

// Spectral MIS: escaping walks score beta / avg(r_u), the one-sample MIS over a uniform hero.
TEST(HeroTracking, OneSampleMisIsUnbiased) {
  const Profile p;
  auto lookup = [&](double t) { return p.at(t); };
  Rng rng(11);
  TrackingCounters counters;
  Moments mom;
  for (int i = 0; i < kWalks; ++i) {
    MisPath<3> path;
    Rgb emitted(0.0);
    const Collision c =
        hero_tracking<3>(lookup, kT0, kT1, p.majorant(), i % 3, path, emitted, rng, counters);
    mom.add(c, path.beta / path.r_u.average(), emitted);
  }
  EXPECT_LT(mom.max_z(p.transmittance()), 4);
  EXPECT_EQ(counters.clamped, 0u);
}

TEST(HeroTracking, ShadowRayTransmittance) {
  // A shadow ray towards a delta light scores T_ray / avg(r_l).
  for (double density : {1.0, 1.05}) {
    Profile p;
    p.density = density;
    auto lookup = [&](double t) { return p.at(t); };
    Rng rng(12);
    TrackingCounters counters;
    std::array<test::MeanVar, 3> T;
    for (int i = 0; i < kWalks; ++i) {
      MisPath<3> path;
      const bool alive =
          hero_ratio_tracking<3>(lookup, kT0, kT1, p.majorant() * 1.05, i % 3, path, rng, counters);
      const Rgb v = alive ? path.beta / path.r_l.average() : Rgb(0.0);
      for (int c = 0; c < 3; ++c) T[c].add(v[c]);
    }
    double z = 0;
    for (int c = 0; c < 3; ++c)
      z = std::max(z, std::abs(T[c].mean - Profile{}.transmittance()[c]) / T[c].std_error());
    if (density == 1)
      EXPECT_LT(z, 4);
    else
      EXPECT_GT(z, 4);
  }
}

// Roulette on the contribution's share (a weight per channel) keeps every channel unbiased,
// whatever the weights, and stops the walk sooner when the weight sits on the densest channel.
TEST(HeroTracking, ShadowRayRouletteOnTheContribution) {
  Profile p;
  auto lookup = [&](double t) { return p.at(t); };
  const Rgb T_ref = p.transmittance();
  const Rgb weight = test::weight_on_densest_channel(T_ref);
  Rng rng(13);
  TrackingCounters plain, weighted;
  std::array<test::MeanVar, 3> T;
  for (int i = 0; i < kWalks; ++i) {
    MisPath<3> path;
    const bool alive = hero_ratio_tracking<3>(lookup, kT0, kT1, p.majorant() * 1.05, i % 3, path,
                                              rng, weighted, &weight);
    const Rgb v = alive ? path.beta / path.r_l.average() : Rgb(0.0);
    for (int c = 0; c < 3; ++c) T[c].add(v[c]);
    MisPath<3> other;
    hero_ratio_tracking<3>(lookup, kT0, kT1, p.majorant() * 1.05, i % 3, other, rng, plain);
  }
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(T[c].mean, T_ref[c], 4 * T[c].std_error()) << "channel " << c;
  EXPECT_LT(weighted.lookups, plain.lookups);
}

// Issue 17: channel 1's majorant fails everywhere (half its bound), channels 0 and 2 bound; issue
// 13: every channel's majorant fails (half its bound). Where a channel's majorant fails its
// technique samples null events in proportion to |mu_n| (failing_share), and the majorant is
// raised for the rest of the segment, so the one-sample MIS over the hero stays unbiased for
// every channel, in free flights and in shadow rays. Clamping a failing channel's mu_n at 0
// biased the first case; giving such a channel no null events at all biased the second.
TEST(HeroTracking, UnbiasedWhereMajorantsFail) {
  for (bool all_fail : {false, true})
    for (double density : {1.0, 1.1}) {  // 1.1: the power to see a 10 % denser medium
      Profile p;
      p.density = density;
      Rgb mu_maj = Profile{}.majorant() * (all_fail ? 0.5 : 1.1);
      mu_maj[1] = 0.5 * Profile{}.majorant()[1];
      auto lookup = [&](double t) { return p.at(t); };
      Rng rng(14);
      TrackingCounters counters;
      Moments mom;
      std::array<test::MeanVar, 3> shadow;
      for (int i = 0; i < kWalks; ++i) {
        MisPath<3> path;
        Rgb emitted(0.0);
        const Collision c =
            hero_tracking<3>(lookup, kT0, kT1, mu_maj, i % 3, path, emitted, rng, counters);
        mom.add(c, path.beta / path.r_u.average(), emitted);
        MisPath<3> ray;
        const bool alive =
            hero_ratio_tracking<3>(lookup, kT0, kT1, mu_maj, i % 3, ray, rng, counters);
        const Rgb T = alive ? ray.beta / ray.r_l.average() : Rgb(0.0);
        for (int ch = 0; ch < 3; ++ch) shadow[ch].add(T[ch]);
      }
      double z = mom.max_z(Profile{}.transmittance());
      for (int ch = 0; ch < 3; ++ch)
        z = std::max(
            z, std::abs(shadow[ch].mean - Profile{}.transmittance()[ch]) / shadow[ch].std_error());
      if (density == 1) {
        EXPECT_LT(z, 4) << (all_fail ? "every" : "one") << " channel's majorant fails";
        EXPECT_EQ(counters.clamped, 0u);
        EXPECT_GT(counters.raised, 0u) << "a failing majorant is raised";
      } else {
        EXPECT_GT(z, 4);
      }
    }
}

}  // namespace spectral_tracking_test
}  // namespace nimbus
