#pragma once
// A contribution weight for the tests of roulette on a shadow ray's share of the contribution.

#include "nimbus/spectral/spectrum.h"

namespace nimbus::test {

// 1 on the channel whose transmittance T is lowest (the one the medium attenuates most) and
// 1e-3 on the others: the weight with which that roulette should stop a walk sooner, since the
// thinner channels' large T no longer keeps it going.
inline Rgb weight_on_densest_channel(const Rgb& T) {
  int dense = 0;
  for (int c = 1; c < 3; ++c)
    if (T[c] < T[dense]) dense = c;
  Rgb weight(1e-3);
  weight[dense] = 1;
  return weight;
}

}  // namespace nimbus::test
