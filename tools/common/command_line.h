// The options of one `tilth` command, parsed from argv by CLI11: positional arguments,
// repeated KEY=VALUE options and flags, with the nearest known names for a misspelt one.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace tilth::cli {

class CommandLine {
 public:
  // `valued` options take the next argument, whatever it is (--set k=v), or what follows
  // their `=` (--set=k=v); `flags` take none; -h is --help where --help is a flag; after
  // `--` every argument is positional. Throws tilth::Error for an unknown option (with the
  // nearest known ones), a missing value or a flag given one.
  CommandLine(int argc, char** argv, int first, const std::set<std::string>& valued,
              const std::set<std::string>& flags);

  const std::vector<std::string>& positional() const { return positional_; }
  std::vector<std::string> values(const std::string& option) const;
  std::optional<std::string> value(const std::string& option) const;
  bool flag(const std::string& option) const { return flags_.count(option) > 0; }
  // The option's value read as a whole: digits only for a count ("5abc", "-1", " 5" and
  // "5.0" are refused), a decimal number for a real. Throws tilth::Error naming the
  // option, the range expected and the text given.
  std::optional<std::uint64_t> count(const std::string& option, std::uint64_t min,
                                     std::uint64_t max) const;
  std::optional<double> real(const std::string& option, double min, double max) const;

 private:
  std::vector<std::string> positional_;
  std::map<std::string, std::vector<std::string>> values_;
  std::set<std::string> flags_;
};

}  // namespace tilth::cli
