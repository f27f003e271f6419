// Argument handling shared by the bench programs: "--flag VALUE" pairs, anything else is a
// positional argument. A flag without its value, or an integer flag whose value is not an
// integer, is one line on stderr and exit 2, as for the nimbus command line.
#pragma once

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

namespace bench_args {

struct Flag {
  const char* name;
  std::function<void(const char*)> set;  // called with the flag's value
};

[[noreturn]] inline void fail(const std::string& message) {
  std::fprintf(stderr, "%s\n", message.c_str());
  std::exit(2);
}

// An integer flag, raised to at least `min`.
inline Flag int_flag(const char* name, int& value, int min = INT_MIN) {
  return {name, [&value, min, name](const char* v) {
            size_t used = 0;
            try {
              const int n = std::stoi(v, &used);
              if (v[used] == '\0') {
                value = std::max(min, n);
                return;
              }
            } catch (const std::exception&) {
            }
            fail(std::string(name) + ": expected an integer, not \"" + v + "\"");
          }};
}

inline Flag string_flag(const char* name, std::string& value) {
  return {name, [&value](const char* v) { value = v; }};
}

// A flag that may be repeated, each value appended.
inline Flag list_flag(const char* name, std::vector<std::string>& values) {
  return {name, [&values](const char* v) { values.push_back(v); }};
}

inline void parse_args(int argc, char** argv, std::initializer_list<Flag> flags,
                       const std::function<void(const char*)>& positional) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const Flag* flag = nullptr;
    for (const Flag& f : flags)
      if (a == f.name) flag = &f;
    if (flag && i + 1 == argc) fail(a + " needs a value");
    if (flag)
      flag->set(argv[++i]);
    else
      positional(argv[i]);
  }
}

}  // namespace bench_args
