#pragma once
// FNV-1a, 64 bits: a checksum of bytes (a file, an octree), not a cryptographic hash.

#include <cstddef>
#include <cstdint>
#include <span>

namespace nimbus {

inline constexpr uint64_t kFnvOffset = 0xcbf29ce484222325ull;

inline uint64_t hash_bytes(std::span<const std::byte> bytes, uint64_t h = kFnvOffset) {
  for (std::byte b : bytes) h = (h ^ uint64_t(b)) * 0x100000001b3ull;
  return h;
}

}  // namespace nimbus
