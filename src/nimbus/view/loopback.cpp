#include "nimbus/view/loopback.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <strings.h>

#include <string>

namespace nimbus {
namespace {

bool loopback_v4(const in_addr& a) {
  return (ntohl(a.s_addr) >> 24) == 127;
}

bool loopback_v6(const in6_addr& a) {
  return IN6_IS_ADDR_LOOPBACK(&a) || (IN6_IS_ADDR_V4MAPPED(&a) && a.s6_addr[12] == 127);
}

}  // namespace

bool is_loopback(const sockaddr* address) {
  if (address->sa_family == AF_INET)
    return loopback_v4(reinterpret_cast<const sockaddr_in*>(address)->sin_addr);
  if (address->sa_family == AF_INET6)
    return loopback_v6(reinterpret_cast<const sockaddr_in6*>(address)->sin6_addr);
  return false;
}

bool loopback_host_header(std::string_view host, int port) {
  std::string name(host);
  // The port, if any, follows the last ':' after a bracketed IPv6 address's ']'.
  const size_t bracket = name.rfind(']');
  const size_t colon = name.rfind(':');
  if (colon != std::string::npos && (bracket == std::string::npos || colon > bracket)) {
    if (name.substr(colon + 1) != std::to_string(port)) return false;
    name.resize(colon);
  }
  if (strcasecmp(name.c_str(), "localhost") == 0) return true;
  in_addr v4{};
  if (inet_pton(AF_INET, name.c_str(), &v4) == 1) return loopback_v4(v4);
  in6_addr v6{};
  return name.size() > 2 && name.front() == '[' && name.back() == ']' &&
         inet_pton(AF_INET6, name.substr(1, name.size() - 2).c_str(), &v6) == 1 && loopback_v6(v6);
}

}  // namespace nimbus
