#pragma once
// Splitting a line of a text format (input log, OBJ) into whitespace-separated fields; a distance in
// metres (the drawing's unit) as a person reads it in a message.
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace fire {

inline std::vector<std::string_view> split_fields(std::string_view line) {
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && blank(line[i])) ++i;
    size_t j = i;
    while (j < line.size() && !blank(line[j])) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

inline std::string format_mm(double metres) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f mm", metres * 1e3);
  return buf;
}

}  // namespace fire
