#include "tilth/json_input.h"

#include <set>
#include <sstream>
#include <vector>

#include "tilth/regular_file.h"

namespace tilth {
namespace {

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

// Builds the document from nlohmann's parser events, checking as it goes. The parser is
// iterative, so nothing recurses before the 65th nested bracket is refused. Objects are
// appended to, not searched: each key is checked once against its object's key set,
// which keeps an ordered_json of n keys O(n log n) where the parser's own builder
// searches the whole object for each key, O(n^2).
template <typename Json>
class Builder {
 public:
  using number_integer_t = typename Json::number_integer_t;
  using number_unsigned_t = typename Json::number_unsigned_t;
  using number_float_t = typename Json::number_float_t;
  using string_t = typename Json::string_t;
  using binary_t = typename Json::binary_t;

  Builder(std::string_view text, const std::string& origin) : text_(text), origin_(origin) {}

  bool null() { return add(nullptr) != nullptr; }
  bool boolean(bool value) { return add(value) != nullptr; }
  bool number_integer(number_integer_t value) { return add(value) != nullptr; }
  bool number_unsigned(number_unsigned_t value) { return add(value) != nullptr; }
  bool number_float(number_float_t value, const string_t&) { return add(value) != nullptr; }
  bool string(string_t& value) { return add(std::move(value)) != nullptr; }
  bool binary(binary_t& value) { return add(Json::binary(std::move(value))) != nullptr; }
  bool start_object(std::size_t) { return open(Json::object(), false); }
  bool start_array(std::size_t) { return open(Json::array(), true); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(string_t& key) {
    Frame& frame = frames_.back();
    frame.key = key;
    if (!frame.keys.insert(key).second) {
      refuse("expected each key once in an object, got \"" + key + "\" again");
    }
    return true;
  }

  bool parse_error(std::size_t position, const std::string& token,
                   const nlohmann::detail::exception& error) {
    // The parser's only out_of_range: a number that overflows a double.
    if (dynamic_cast<const nlohmann::detail::out_of_range*>(&error) != nullptr) {
      refuse("expected a number within double range (magnitude below 1.8e308), got " + token);
    }
    const auto [line, column] = line_and_column(text_, position == 0 ? 0 : position - 1);
    throw JsonError(origin_, "", line, column, parse_error_reason(error.what()));
  }

  Json take() { return std::move(document_); }

 private:
  struct Frame {
    Json* container;
    bool array;
    std::string key;  // of the value being read, in an object
    std::set<std::string> keys;
  };

  // Where the next value goes. An array's value being read is its open last element, or,
  // in the innermost container, the one after its last.
  std::string pointer() const {
    std::string text;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      const Frame& frame = frames_[i];
      const bool innermost = i + 1 == frames_.size();
      text += "/" + (frame.array ? std::to_string(frame.container->size() - (innermost ? 0 : 1))
                                 : json_pointer_token(frame.key));
    }
    return text;
  }

  [[noreturn]] void refuse(const std::string& reason) const {
    throw JsonError(origin_, pointer(), 0, 0, reason);
  }

  Json* add(Json value) {
    if (frames_.empty()) {
      document_ = std::move(value);
      return &document_;
    }
    Frame& frame = frames_.back();
    if (frame.array) {
      frame.container->push_back(std::move(value));
      return &frame.container->back();
    }
    auto& object = frame.container->template get_ref<typename Json::object_t&>();
    if constexpr (std::is_same_v<typename Json::object_t, nlohmann::ordered_json::object_t>) {
      // Appended, not searched: key() refused a second use of the key.
      object.Container::emplace_back(frame.key, std::move(value));
      return &object.back().second;
    } else {
      return &object.emplace(frame.key, std::move(value)).first->second;
    }
  }

  bool open(Json container, bool array) {
    if (frames_.size() >= kMaxJsonDepth) {
      refuse("expected at most " + std::to_string(kMaxJsonDepth) +
             " nested arrays and objects, got more");
    }
    Json* opened = add(std::move(container));
    frames_.push_back({opened, array, {}, {}});
    return true;
  }

  bool close() {
    frames_.pop_back();
    return true;
  }

  std::string_view text_;
  const std::string& origin_;
  Json document_;
  // The open containers, outermost first. A container's address holds while it is open:
  // its parent grows only after it closes.
  std::vector<Frame> frames_;
};

template <typename Json>
Json parse(std::string_view text, const std::string& origin, JsonSyntax syntax) {
  Builder<Json> builder(text, origin);
  Json::sax_parse(text, &builder, nlohmann::json::input_format_t::json, /*strict=*/true,
                  syntax.comments);
  return builder.take();
}

}  // namespace

std::string json_pointer_token(const std::string& key) {
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
  std::error_code error;
  if (!std::filesystem::exists(file, error)) {
    throw JsonError(name, "", 0, 0, "cannot read " + std::string(what));
  }
  try {
    return read_regular_file(file, kMaxJsonFileBytes, what);
  } catch (const Error& refused) {
    // "NAME: REASON" as a JsonError, so that readers that collect problems keep its parts.
    const std::string_view text = refused.what();
    const std::string_view reason =
        text.starts_with(name + ": ") ? text.substr(name.size() + 2) : text;
    throw JsonError(name, "", 0, 0, std::string(reason));
  }
}

}  // namespace tilth
