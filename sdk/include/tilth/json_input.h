// The one way Tilth reads JSON it is given (graph files, calibration files, recordings,
// option values): well-formed is not enough; duplicate keys, deep nesting, numbers
// beyond double range and files that are not small regular files are refused, located.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "tilth/error.h"

namespace tilth {

// Deeper than any file of Tilth needs (a graph file nests 5 levels), shallow enough that
// every recursive walk of the document stays far from the stack's end.
inline constexpr std::size_t kMaxJsonDepth = 64;
// A graph or calibration file is a few kB; 16 MiB is a file that is not one of them.
inline constexpr std::uintmax_t kMaxJsonFileBytes = 16u << 20;

// `what()` is "ORIGIN:POINTER: REASON", "ORIGIN:LINE:COLUMN: malformed JSON: REASON" or
// "ORIGIN: REASON"; the parts stay apart for readers that collect problems.
class JsonError : public Error {
 public:
  JsonError(std::string origin, std::string pointer, int line, int column, std::string reason);

  const std::string& origin() const { return origin_; }
  const std::string& pointer() const { return pointer_; }  // RFC 6901; empty when unknown
  int line() const { return line_; }                       // 1-based, malformed JSON only
  int column() const { return column_; }
  const std::string& reason() const { return reason_; }
  bool malformed() const { return line_ > 0; }

 private:
  std::string origin_;
  std::string pointer_;
  int line_;
  int column_;
  std::string reason_;
};

struct JsonSyntax {
  bool comments = false;  // allow // and /* */ comments (graph and variants files)
};

// Throws JsonError: malformed (line and column), a key twice in one object, nesting
// deeper than kMaxJsonDepth, or a number beyond double range (each at its JSON pointer).
nlohmann::json parse_json(std::string_view text, const std::string& origin, JsonSyntax syntax = {});
// The same, keeping the keys in the order written.
nlohmann::ordered_json parse_ordered_json(std::string_view text, const std::string& origin,
                                          JsonSyntax syntax = {});

// `key` as one token of a JSON pointer (RFC 6901: '~' and '/' escaped as ~0 and ~1).
std::string json_pointer_token(const std::string& key);

// The text of a JSON file: a regular file (never a device or a FIFO, which could block or
// never end) of at most kMaxJsonFileBytes. `what` names the file's kind in the error:
// "rig.calib.json: cannot read calibration file".
std::string read_json_text(const std::filesystem::path& file, std::string_view what);

}  // namespace tilth
