#pragma once
// Which addresses and Host headers are this machine's own, for `nimbus view`'s server: bound to
// the loopback it serves this machine only, and answers only requests whose Host header names
// the loopback, so that a DNS name rebound to 127.0.0.1 cannot let another site's page talk to
// it through the browser (such a page's Host is its own name).

#include <sys/socket.h>

#include <string_view>

namespace nimbus {

// 127.0.0.0/8, ::1, or ::ffff:127.0.0.0/104.
bool is_loopback(const sockaddr* address);

// `host` (a Host header's value) is "localhost" or a loopback address (127.x.y.z, [::1]), alone
// or with `port`.
bool loopback_host_header(std::string_view host, int port);

}  // namespace nimbus
