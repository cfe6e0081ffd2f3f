#include "command_line.h"

#include <algorithm>
#include <charconv>
#include <sstream>

#include <CLI/CLI.hpp>

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

bool looks_like_option(const std::string& arg) { return arg.size() > 1 && arg.front() == '-'; }

}  // namespace

CommandLine::CommandLine(int argc, char** argv, int first, const std::set<std::string>& valued,
                         const std::set<std::string>& flags) {
  std::vector<std::string> known(valued.begin(), valued.end());
  known.insert(known.end(), flags.begin(), flags.end());
  const auto unknown = [&known](const std::string& name) {
    return Error("unknown option " + name + did_you_mean(name, known) + " (see --help)");
  };

  // What CLI11 reads: each option followed by its value (which CLI11 takes whatever it
  // looks like, even empty), flags alone, positional arguments; after `--`, only
  // positional arguments, which CLI11 does not see.
  std::vector<std::string> args;
  std::vector<std::string> after_separator;
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") {
      after_separator.assign(argv + i + 1, argv + argc);
      break;
    }
    const std::string name = arg.substr(0, arg.find('='));
    if (valued.count(name)) {
      args.push_back(name);
      if (name != arg) {
        args.push_back(arg.substr(name.size() + 1));
      } else if (i + 1 < argc) {
        args.push_back(argv[++i]);
      } else {
        throw Error(arg + " needs a value");
      }
    } else if (flags.count(name) && name != arg) {
      throw Error(name + " takes no value (see --help)");
    } else if (arg.starts_with("-") && !arg.starts_with("--") && arg != "-" &&
               !(arg == "-h" && flags.count("--help"))) {
      throw unknown(arg);  // CLI11 would read "-hq" as -h and -q
    } else {
      args.push_back(arg);
    }
  }

  CLI::App app;
  app.set_help_flag();
  app.allow_extras();  // positional arguments and unknown options, told apart below
  std::map<std::string, std::vector<std::string>> given;
  for (const auto& option : valued) app.add_option(option, given[option])->allow_extra_args(false);
  for (const auto& option : flags) app.add_flag(option == "--help" ? "-h,--help" : option);
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    app.parse(args);
  } catch (const CLI::ParseError& error) {
    throw Error(std::string(error.what()) + " (see --help)");
  }

  for (const auto& arg : app.remaining()) {
    if (looks_like_option(arg)) throw unknown(arg.substr(0, arg.find('=')));
    positional_.push_back(arg);
  }
  positional_.insert(positional_.end(), after_separator.begin(), after_separator.end());
  for (auto& [option, values] : given)
    if (!values.empty()) values_[option] = std::move(values);
  for (const auto& option : flags)
    if (app.count(option) > 0) flags_.insert(option);
}

std::vector<std::string> CommandLine::values(const std::string& option) const {
  const auto found = values_.find(option);
  return found == values_.end() ? std::vector<std::string>{} : found->second;
}

std::optional<std::string> CommandLine::value(const std::string& option) const {
  const auto found = values_.find(option);
  if (found == values_.end()) return std::nullopt;
  return found->second.back();
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
