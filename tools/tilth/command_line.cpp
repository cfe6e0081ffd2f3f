#include "command_line.h"

#include "tilth/error.h"

namespace tilth::cli {

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
    } else if (arg.starts_with("-") && arg != "-") {
      throw Error("unknown option " + arg + " (see --help)");
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

}  // namespace tilth::cli
