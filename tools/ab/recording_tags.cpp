#include "recording_tags.h"

#include <algorithm>
#include <fstream>
#include <string>

#include "tilth/error.h"

namespace tilth::ab {
namespace {

std::vector<std::string> fields_of(const std::string& line) {
  std::vector<std::string> fields(1);
  for (const char c : line) {
    if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

}  // namespace

void apply_tags_file(const std::filesystem::path& file, std::vector<Recording>& recordings) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot read the tags file");
  std::string line;
  std::size_t number = 1;
  if (!std::getline(in, line)) throw Error(file.string() + ": empty; expected recording,KEY...");
  const std::vector<std::string> header = fields_of(line);
  if (header.size() < 2 || header.front() != "recording") {
    throw Error(file.string() + ":1: expected the header recording,KEY... (a column per tag)");
  }
  for (std::size_t k = 1; k < header.size(); ++k) {
    if (header[k].empty()) {
      throw Error(file.string() + ":1: column " + std::to_string(k + 1) + " has no tag name");
    }
  }
  while (std::getline(in, line)) {
    ++number;
    const std::string where = file.string() + ":" + std::to_string(number);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (line.find('"') != std::string::npos) {
      throw Error(where + ": quotes are not read; tags are plain text without commas");
    }
    const std::vector<std::string> fields = fields_of(line);
    if (fields.size() != header.size()) {
      throw Error(where + ": " + std::to_string(fields.size()) + " fields, expected " +
                  std::to_string(header.size()) + " as in the header");
    }
    const auto recording =
        std::find_if(recordings.begin(), recordings.end(),
                     [&](const Recording& known) { return known.name == fields.front(); });
    if (recording == recordings.end()) {
      throw Error(where + ": no recording named '" + fields.front() + "' among the " +
                  std::to_string(recordings.size()) +
                  " given (names as in the report: folder name or file stem)");
    }
    for (std::size_t k = 1; k < header.size(); ++k) {
      if (!fields[k].empty()) recording->tags[header[k]] = fields[k];
    }
  }
}

}  // namespace tilth::ab
