#include "command_usage.h"

#include <cctype>
#include <vector>

namespace tilth::cli {
namespace {

std::vector<std::string_view> lines_of(std::string_view text) {
  std::vector<std::string_view> lines;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    lines.push_back(text.substr(0, end));
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return lines;
}

// A line that names a command: two spaces, then a word.
bool starts_a_command(std::string_view line) {
  return line.size() > 2 && line.starts_with("  ") &&
         !std::isspace(static_cast<unsigned char>(line[2]));
}

}  // namespace

std::optional<std::string> command_usage(std::string_view usage, std::string_view command) {
  const std::vector<std::string_view> lines = lines_of(usage);
  if (lines.empty()) return std::nullopt;
  // "usage: tilth TOOL COMMAND ARGS" -> "usage: tilth TOOL"
  std::string_view head = lines[0];
  if (const std::size_t at = head.find(" COMMAND"); at != std::string_view::npos) {
    head = head.substr(0, at);
  }
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::string_view line = lines[i];
    if (!starts_a_command(line) || !line.substr(2).starts_with(command)) continue;
    const std::string_view after = line.substr(2 + command.size());
    if (!after.empty() && after[0] != ' ') continue;  // "import" is not "import-masks"
    std::string text = std::string(head) + "\n\n" + std::string(line) + "\n";
    for (++i; i < lines.size(); ++i) {
      const std::string_view more = lines[i];
      if (more.empty() || !more.starts_with("   ")) break;
      text += std::string(more) + "\n";
    }
    return text;
  }
  return std::nullopt;
}

std::string help_text(std::string_view usage, const std::vector<std::string>& positional) {
  if (positional.empty()) return std::string(usage);
  return command_usage(usage, positional[0]).value_or(std::string(usage));
}

}  // namespace tilth::cli
