// The options of one `tilth` command, parsed from argv: positional arguments, repeated
// KEY=VALUE options and flags.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace tilth::cli {

class CommandLine {
 public:
  // `valued` options take the next argument (--set k=v); `flags` take none. Throws
  // tilth::Error for an unknown option or a missing value.
  CommandLine(int argc, char** argv, int first, const std::set<std::string>& valued,
              const std::set<std::string>& flags);

  const std::vector<std::string>& positional() const { return positional_; }
  std::vector<std::string> values(const std::string& option) const;
  std::optional<std::string> value(const std::string& option) const;
  bool flag(const std::string& option) const { return flags_.count(option) > 0; }

 private:
  std::vector<std::string> positional_;
  std::multimap<std::string, std::string> values_;
  std::set<std::string> flags_;
};

}  // namespace tilth::cli
