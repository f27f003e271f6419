// Argument handling shared by the bench programs: "--flag VALUE" pairs, anything else is a
// positional argument. A flag given last, without its value, is taken as a positional argument,
// and a value that is not a number ends the program through std::stoi's exception: these are
// developer tools, and their behaviour is kept as it was before they shared this file.
#pragma once

#include <algorithm>
#include <climits>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

namespace bench_args {

struct Flag {
  const char* name;
  std::function<void(const char*)> set;  // called with the flag's value
};

// An integer flag, raised to at least `min`.
inline Flag int_flag(const char* name, int& value, int min = INT_MIN) {
  return {name, [&value, min](const char* v) { value = std::max(min, std::stoi(v)); }};
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
      if (a == f.name && i + 1 < argc) flag = &f;
    if (flag)
      flag->set(argv[++i]);
    else
      positional(argv[i]);
  }
}

}  // namespace bench_args
