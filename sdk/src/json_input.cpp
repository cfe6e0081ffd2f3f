// nlohmann's parser is iterative and calls back at each key, value and bracket before it
// goes deeper, so the checks below run before a hostile document can build anything
// large: a key seen twice, the 65th nested bracket, a number that overflows to infinity.
#include "tilth/json_input.h"

#include <fstream>
#include <set>
#include <sstream>
#include <vector>

namespace tilth {
namespace {

// RFC 6901: '~' and '/' inside a key are escaped.
std::string pointer_token(const std::string& key) {
  std::string escaped;
  for (char c : key) {
    if (c == '~') {
      escaped += "~0";
    } else if (c == '/') {
      escaped += "~1";
    } else {
      escaped += c;
    }
  }
  return escaped;
}

std::pair<int, int> line_and_column(std::string_view text, std::size_t byte) {
  int line = 1;
  int column = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

// nlohmann's messages start with "[json.exception.parse_error.101] parse error at line
// 3, column 5: "; keep what follows.
std::string parse_error_reason(const std::string& what) {
  const auto colon = what.find(": ");
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

// "number overflow parsing '1e999'" -> "1e999"
std::string overflowing_number(const std::string& what) {
  const auto open = what.find('\'');
  const auto close = what.rfind('\'');
  return open == std::string::npos || close <= open ? "?" : what.substr(open + 1, close - open - 1);
}

// Where the parser is: one frame per open object or array, with the key or index of the
// value being read in it.
class Position {
 public:
  explicit Position(const std::string& origin) : origin_(origin) {}

  template <typename Json>
  bool on_event(nlohmann::detail::parse_event_t event, const Json& parsed) {
    using Event = nlohmann::detail::parse_event_t;
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        if (frames_.size() >= kMaxJsonDepth) {
          refuse("expected at most " + std::to_string(kMaxJsonDepth) +
                 " nested arrays and objects, got more");
        }
        frames_.push_back({event == Event::array_start, 0, {}, {}});
        break;
      case Event::key: {
        Frame& frame = frames_.back();
        frame.key = parsed.template get<std::string>();
        if (!frame.keys.insert(frame.key).second) {
          refuse("expected each key once in an object, got \"" + frame.key + "\" again");
        }
        break;
      }
      case Event::object_end:
      case Event::array_end:
        frames_.pop_back();
        next_value();
        break;
      case Event::value:
        next_value();
        break;
    }
    return true;
  }

  std::string pointer() const {
    std::string text;
    for (const Frame& frame : frames_) {
      text += "/" + (frame.array ? std::to_string(frame.index) : pointer_token(frame.key));
    }
    return text;
  }

  [[noreturn]] void refuse(const std::string& reason) const {
    throw JsonError(origin_, pointer(), 0, 0, reason);
  }

 private:
  struct Frame {
    bool array;
    std::size_t index;
    std::string key;
    std::set<std::string> keys;
  };

  void next_value() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }

  const std::string& origin_;
  std::vector<Frame> frames_;
};

template <typename Json>
Json parse(std::string_view text, const std::string& origin, JsonSyntax syntax) {
  Position position(origin);
  const typename Json::parser_callback_t check =
      [&position](int, nlohmann::detail::parse_event_t event, Json& parsed) {
        return position.on_event(event, parsed);
      };
  try {
    return Json::parse(text, check, /*allow_exceptions=*/true, syntax.comments);
  } catch (const nlohmann::json::parse_error& error) {
    const auto [line, column] = line_and_column(text, error.byte == 0 ? 0 : error.byte - 1);
    throw JsonError(origin, "", line, column, parse_error_reason(error.what()));
  } catch (const nlohmann::json::out_of_range& error) {
    // 406, the only one the parser throws: a number that overflows a double.
    position.refuse("expected a number within double range (magnitude below 1.8e308), got " +
                    overflowing_number(error.what()));
  }
}

std::string file_kind(std::filesystem::file_type type) {
  using std::filesystem::file_type;
  switch (type) {
    case file_type::directory:
      return "a folder";
    case file_type::character:
      return "a character device";
    case file_type::block:
      return "a block device";
    case file_type::fifo:
      return "a FIFO";
    case file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

}  // namespace

JsonError::JsonError(std::string origin, std::string pointer, int line, int column,
                     std::string reason)
    : Error(origin +
            (line > 0
                 ? ":" + std::to_string(line) + ":" + std::to_string(column) + ": malformed JSON: "
                 : (pointer.empty() ? "" : ":" + pointer) + ": ") +
            reason),
      origin_(std::move(origin)),
      pointer_(std::move(pointer)),
      line_(line),
      column_(column),
      reason_(std::move(reason)) {}

nlohmann::json parse_json(std::string_view text, const std::string& origin, JsonSyntax syntax) {
  return parse<nlohmann::json>(text, origin, syntax);
}

nlohmann::ordered_json parse_ordered_json(std::string_view text, const std::string& origin,
                                          JsonSyntax syntax) {
  return parse<nlohmann::ordered_json>(text, origin, syntax);
}

std::string read_json_text(const std::filesystem::path& file, std::string_view what) {
  const std::string name = file.string();
  const std::string cannot = "cannot read " + std::string(what);
  std::error_code error;
  const auto status = std::filesystem::status(file, error);
  if (error || status.type() == std::filesystem::file_type::not_found) {
    throw JsonError(name, "", 0, 0, cannot);
  }
  if (status.type() != std::filesystem::file_type::regular) {
    throw JsonError(name, "", 0, 0,
                    cannot + ": expected a regular file, got " + file_kind(status.type()));
  }
  const auto too_large = [&](const std::string& size) {
    return JsonError(name, "", 0, 0,
                     cannot + ": expected at most " + std::to_string(kMaxJsonFileBytes >> 20) +
                         " MiB, got " + size);
  };
  if (const auto size = std::filesystem::file_size(file, error);
      !error && size > kMaxJsonFileBytes) {
    throw too_large(std::to_string(size) + " bytes");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw JsonError(name, "", 0, 0, cannot);
  // Counted as read too: the file may have grown since.
  std::string text;
  char chunk[65536];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxJsonFileBytes) throw too_large("more");
  }
  if (in.bad()) throw JsonError(name, "", 0, 0, cannot);
  return text;
}

}  // namespace tilth
