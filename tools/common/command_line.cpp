#include "command_line.h"

#include <charconv>
#include <sstream>

#include "framework/nearest_names.h"
#include "tilth/error.h"

namespace tilth::cli {
namespace {

template <typename Number>
std::optional<Number> whole_text_number(const std::string& text) {
  Number value{};
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || stop != end || text.empty()) return std::nullopt;
  return value;
}

template <typename Number>
[[noreturn]] void refuse(const std::string& option, const std::string& what, Number min, Number max,
                         const std::string& text) {
  std::ostringstream message;
  message << option << ": expected " << what << " in [" << min << ", " << max << "], got '" << text
          << "'";
  throw Error(message.str());
}

}  // namespace

CommandLine::CommandLine(int argc, char** argv, int first, const std::set<std::string>& valued,
                         const std::set<std::string>& flags) {
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    std::optional<std::string> inline_value;
    if (arg.starts_with("--") && arg.find('=') != std::string::npos && !valued.count(arg)) {
      const auto equals = arg.find('=');
      if (valued.count(arg.substr(0, equals))) {
        inline_value = arg.substr(equals + 1);
        arg = arg.substr(0, equals);
      }
    }
    if (valued.count(arg)) {
      if (!inline_value && i + 1 >= argc) throw Error(arg + " needs a value");
      values_.emplace(arg, inline_value ? *inline_value : argv[++i]);
    } else if (flags.count(arg)) {
      flags_.insert(arg);
    } else if (arg == "-h" && flags.count("--help")) {
      flags_.insert("--help");
    } else if (arg.starts_with("-") && arg != "-") {
      std::vector<std::string> known(valued.begin(), valued.end());
      known.insert(known.end(), flags.begin(), flags.end());
      throw Error("unknown option " + arg + did_you_mean(arg, known) + " (see --help)");
    } else {
      positional_.push_back(arg);
    }
  }
}

std::vector<std::string> CommandLine::values(const std::string& option) const {
  std::vector<std::string> result;
  auto [begin, end] = values_.equal_range(option);
  for (auto it = begin; it != end; ++it) result.push_back(it->second);
  return result;
}

std::optional<std::string> CommandLine::value(const std::string& option) const {
  auto all = values(option);
  if (all.empty()) return std::nullopt;
  return all.back();
}

std::optional<std::uint64_t> CommandLine::count(const std::string& option, std::uint64_t min,
                                                std::uint64_t max) const {
  const auto text = value(option);
  if (!text) return std::nullopt;
  const auto number = whole_text_number<std::uint64_t>(*text);
  if (!number || *number < min || *number > max) refuse(option, "a whole number", min, max, *text);
  return number;
}

std::optional<double> CommandLine::real(const std::string& option, double min, double max) const {
  const auto text = value(option);
  if (!text) return std::nullopt;
  const auto number = whole_text_number<double>(*text);
  if (!number || !(*number >= min && *number <= max)) refuse(option, "a number", min, max, *text);
  return number;
}

}  // namespace tilth::cli
