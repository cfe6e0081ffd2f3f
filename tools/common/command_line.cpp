#include "command_line.h"

#include <CLI/CLI.hpp>
#include <algorithm>
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

bool looks_like_option(const std::string& arg) {
  return arg.size() > 1 && arg.front() == '-' && arg != "--";
}

}  // namespace

CommandLine::CommandLine(int argc, char** argv, int first, const std::set<std::string>& valued,
                         const std::set<std::string>& flags) {
  CLI::App app;
  app.set_help_flag();
  app.allow_extras();  // positional arguments and unknown options, told apart below
  std::map<std::string, std::vector<std::string>> given;
  for (const auto& option : valued) app.add_option(option, given[option])->allow_extra_args(false);
  for (const auto& option : flags) app.add_flag(option == "--help" ? "-h,--help" : option);

  // A value is whatever follows its option, as a user who writes `--set -x` expects.
  std::vector<std::string> args;
  for (int i = first; i < argc; ++i) {
    args.emplace_back(argv[i]);
    if (!valued.count(argv[i])) continue;
    if (i + 1 == argc) throw Error(args.back() + " needs a value");
    if (looks_like_option(argv[i + 1])) args.back() += std::string("=") + argv[++i];
  }
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    app.parse(args);
  } catch (const CLI::ParseError& error) {
    throw Error(std::string(error.what()) + " (see --help)");
  }

  for (const auto& arg : app.remaining()) {
    if (looks_like_option(arg)) {
      std::vector<std::string> known(valued.begin(), valued.end());
      known.insert(known.end(), flags.begin(), flags.end());
      const std::string name = arg.substr(0, arg.find('='));
      throw Error("unknown option " + name + did_you_mean(name, known) + " (see --help)");
    }
    positional_.push_back(arg);
  }
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
