// The declaration of one stage parameter: its type, default, allowed values, unit and
// a one-line description. The graph loader checks every value against it before a
// stage is made, and `tilth describe` prints it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace tilth {

enum class ParamType {
  kBool,
  kInteger,
  kNumber,
  kString,
  kPath,        // a file the stage reads; relative paths resolve against the graph file
  kOutputPath,  // a file the stage writes; relative paths resolve against the working directory
  kChoice,      // a string from a fixed list
  kJson,        // any JSON value; the stage checks its shape
};

std::string_view to_string(ParamType type);

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::kNumber;
  nlohmann::json default_value;  // null: the parameter is required
  std::optional<double> min;
  std::optional<double> max;
  std::vector<std::string> choices;
  std::string unit;
  std::string description;

  static ParamSpec boolean(std::string name, bool default_value);
  static ParamSpec integer(std::string name, std::optional<std::int64_t> default_value);
  static ParamSpec number(std::string name, std::optional<double> default_value);
  static ParamSpec string(std::string name, std::optional<std::string> default_value);
  static ParamSpec path(std::string name, std::optional<std::string> default_value);
  static ParamSpec output_path(std::string name, std::optional<std::string> default_value);
  static ParamSpec choice(std::string name, std::vector<std::string> choices,
                          std::string default_value);
  static ParamSpec json(std::string name, nlohmann::json default_value);

  ParamSpec& range(std::optional<double> minimum, std::optional<double> maximum);
  ParamSpec& in_unit(std::string unit_name);
  ParamSpec& describe(std::string text);

  bool required() const { return default_value.is_null() && type != ParamType::kJson; }

  // Empty when `value` is acceptable, otherwise what was expected ("a number in
  // [0, 1]", "one of 'median', 'trimmed_mean'").
  std::string check(const nlohmann::json& value) const;
};

}  // namespace tilth
