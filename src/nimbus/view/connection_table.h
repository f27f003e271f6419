#pragma once
// The connections of `nimbus view`'s server and which of them to drop, so that slow or idle
// clients cannot lock others out (issue 44). Each connection has a deadline: its whole request
// (headers and body) must arrive within `request` of the connection's start or of its last
// answer, however slowly the bytes trickle in, and an answer must be taken within `answer`. At
// most `total` connections are kept, and at most `per_client` from one address: a newcomer
// beyond either drops the stalest connection that is waiting for a request (the one nearest its
// deadline), so that a flood of idle connections makes room for a client with a request; only
// when every other connection is being answered is the newcomer itself dropped.
//
// Not thread-safe: the server calls it under a lock. Connections are named by their socket.

#include <chrono>
#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

namespace nimbus {

class ConnectionTable {
 public:
  using Clock = std::chrono::steady_clock;
  struct Limits {
    size_t total = 256;
    size_t per_client = 128;
    Clock::duration request = std::chrono::seconds(5);
    Clock::duration answer = std::chrono::seconds(5);
  };

  explicit ConnectionTable(Limits limits) : limits_(limits) {}

  // A new connection from `client` (its address); returns the sockets to drop now.
  std::vector<int> add(int socket, const std::string& client, Clock::time_point now);
  // Its request arrived and an answer is on its way.
  void answering(int socket, Clock::time_point now);
  // The answer was taken: the next request may come.
  void answered(int socket, Clock::time_point now);
  void remove(int socket);
  // The sockets past their deadline, each returned once.
  std::vector<int> expired(Clock::time_point now);
  // The earliest deadline of a connection not yet dropped; Clock::time_point::max() if none.
  Clock::time_point next_deadline() const;
  // Connections not yet dropped.
  size_t open() const;

 private:
  struct Entry {
    std::string client;
    Clock::time_point deadline;
    bool waiting = true;   // for a request (else being answered)
    bool dropped = false;  // returned to be dropped; it leaves at remove()
  };
  // The waiting connection nearest its deadline, from `client` ("": any), other than `except`.
  int stalest(const std::string& client, int except) const;
  size_t open_from(const std::string& client) const;

  Limits limits_;
  std::unordered_map<int, Entry> entries_;
};

}  // namespace nimbus
