#pragma once
// Whether this build runs under AddressSanitizer, whose allocator aborts the process where a
// failed allocation would otherwise throw std::bad_alloc.

namespace nimbus::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

}  // namespace nimbus::test
