// Where something was written: a graph file and a JSON pointer into it, a line and
// column for malformed JSON, or a command-line option.
#pragma once

#include <string>

namespace tilth {

struct Location {
  std::string file;     // a path, or "command line"
  std::string pointer;  // a JSON pointer ("/nodes/depth/type"), or the option ("--set a.b")
  int line = 0;         // 1-based, for malformed JSON only
  int column = 0;

  // "graphs/seeder.json:/nodes/depth/type", "graphs/seeder.json:3:14", "graphs/x.json"
  std::string text() const;
  Location child(const std::string& key) const;
};

}  // namespace tilth
