// One command's part of a tool's usage text, for `tilth TOOL COMMAND --help`: the lines
// from the one that starts with the command (indented two spaces) to the next command.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tilth::cli {

// `usage` starts with "usage: tilth TOOL COMMAND ARGS", then lists each command on a line
// of its own indented two spaces, its description and options indented further. Returns
// "usage: tilth TOOL" followed by the command's lines, or nullopt for a command the text
// does not list.
std::optional<std::string> command_usage(std::string_view usage, std::string_view command);

// What `tilth TOOL [COMMAND] --help` prints: the command's part of `usage` when the first
// of `positional` names one, else the whole.
std::string help_text(std::string_view usage, const std::vector<std::string>& positional);

}  // namespace tilth::cli
