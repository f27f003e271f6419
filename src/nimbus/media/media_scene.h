#pragma once
// What the media layer needs of a scene, and no more (docs/architecture.md): the media, the
// objects that may hold them (their function, conservative bounds and medium index, -1 for
// none), which objects make up the field of index-matched media, and the majorant octrees. The
// renderer's Scene satisfies it; so does any plain struct with these members.

#include <concepts>
#include <ranges>

#include "nimbus/frep/tape.h"
#include "nimbus/math/box.h"
#include "nimbus/media/medium.h"
#include "nimbus/media/octree.h"

namespace nimbus {

// The media and their holders: enough to say which media are present at a point.
template <class S>
concept MediumHolders = requires(const S& s, int i) {
  { s.media[i] } -> std::convertible_to<const Medium&>;
  { s.objects[i].tape } -> std::convertible_to<const Tape&>;
  { s.objects[i].bounds } -> std::convertible_to<const Box&>;
  { s.objects[i].medium } -> std::convertible_to<int>;
  { s.field_objects } -> std::ranges::range;
};

// Holders plus the majorant octrees: the field's, and one per object (used for the solid ones
// holding a medium, which displace the media around them).
template <class S>
concept MediaScene = MediumHolders<S> && requires(const S& s, int i) {
  { s.field_octree } -> std::convertible_to<const MajorantOctree&>;
  { s.solid_octrees.at(i) } -> std::convertible_to<const MajorantOctree&>;
};

}  // namespace nimbus
