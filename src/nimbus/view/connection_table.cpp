#include "nimbus/view/connection_table.h"

#include <algorithm>

namespace nimbus {

std::vector<int> ConnectionTable::add(int socket, const std::string& client,
                                      Clock::time_point now) {
  entries_[socket] = Entry{client, now + limits_.request};
  std::vector<int> drop;
  const auto make_room = [&](const std::string& from, size_t limit) {
    while ((from.empty() ? open() : open_from(from)) > limit) {
      int victim = stalest(from, socket);
      if (victim < 0) victim = socket;  // every other one is being answered
      entries_[victim].dropped = true;
      drop.push_back(victim);
      if (victim == socket) return;
    }
  };
  make_room(client, limits_.per_client);
  if (!entries_[socket].dropped) make_room("", limits_.total);
  return drop;
}

void ConnectionTable::answering(int socket, Clock::time_point now) {
  const auto it = entries_.find(socket);
  if (it == entries_.end()) return;
  it->second.waiting = false;
  it->second.deadline = now + limits_.answer;
}

void ConnectionTable::answered(int socket, Clock::time_point now) {
  const auto it = entries_.find(socket);
  if (it == entries_.end()) return;
  it->second.waiting = true;
  it->second.deadline = now + limits_.request;
}

void ConnectionTable::remove(int socket) {
  entries_.erase(socket);
}

std::vector<int> ConnectionTable::expired(Clock::time_point now) {
  std::vector<int> late;
  for (auto& [socket, e] : entries_)
    if (!e.dropped && e.deadline <= now) {
      e.dropped = true;
      late.push_back(socket);
    }
  return late;
}

ConnectionTable::Clock::time_point ConnectionTable::next_deadline() const {
  Clock::time_point next = Clock::time_point::max();
  for (const auto& [socket, e] : entries_)
    if (!e.dropped) next = std::min(next, e.deadline);
  return next;
}

size_t ConnectionTable::open() const {
  return size_t(std::count_if(entries_.begin(), entries_.end(),
                              [](const auto& kv) { return !kv.second.dropped; }));
}

size_t ConnectionTable::open_from(const std::string& client) const {
  return size_t(std::count_if(entries_.begin(), entries_.end(), [&](const auto& kv) {
    return !kv.second.dropped && kv.second.client == client;
  }));
}

int ConnectionTable::stalest(const std::string& client, int except) const {
  int best = -1;
  Clock::time_point best_deadline = Clock::time_point::max();
  for (const auto& [socket, e] : entries_) {
    if (socket == except || e.dropped || !e.waiting) continue;
    if (!client.empty() && e.client != client) continue;
    if (best < 0 || e.deadline < best_deadline || (e.deadline == best_deadline && socket < best)) {
      best = socket;
      best_deadline = e.deadline;
    }
  }
  return best;
}

}  // namespace nimbus
