#include "tilth/param_spec.h"

#include <sstream>

namespace tilth {
namespace {

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string range_text(const ParamSpec& spec) {
  if (spec.min && spec.max) {
    return " in [" + format_number(*spec.min) + ", " + format_number(*spec.max) + "]";
  }
  if (spec.min) return " >= " + format_number(*spec.min);
  if (spec.max) return " <= " + format_number(*spec.max);
  return "";
}

std::string choices_text(const std::vector<std::string>& choices) {
  std::string text;
  for (const auto& choice : choices) {
    if (!text.empty()) text += ", ";
    text += "'" + choice + "'";
  }
  return text;
}

bool in_range(const ParamSpec& spec, double value) {
  return (!spec.min || value >= *spec.min) && (!spec.max || value <= *spec.max);
}

ParamSpec make(std::string name, ParamType type, nlohmann::json default_value) {
  ParamSpec spec;
  spec.name = std::move(name);
  spec.type = type;
  spec.default_value = std::move(default_value);
  return spec;
}

template <class T>
nlohmann::json or_null(const std::optional<T>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json();
}

}  // namespace

std::string_view to_string(ParamType type) {
  switch (type) {
    case ParamType::kBool:
      return "bool";
    case ParamType::kInteger:
      return "integer";
    case ParamType::kNumber:
      return "number";
    case ParamType::kString:
      return "string";
    case ParamType::kPath:
      return "path";
    case ParamType::kOutputPath:
      return "output path";
    case ParamType::kChoice:
      return "choice";
    case ParamType::kJson:
      return "json";
  }
  return "unknown";
}

ParamSpec ParamSpec::boolean(std::string name, bool default_value) {
  return make(std::move(name), ParamType::kBool, default_value);
}
ParamSpec ParamSpec::integer(std::string name, std::optional<std::int64_t> default_value) {
  return make(std::move(name), ParamType::kInteger, or_null(default_value));
}
ParamSpec ParamSpec::number(std::string name, std::optional<double> default_value) {
  return make(std::move(name), ParamType::kNumber, or_null(default_value));
}
ParamSpec ParamSpec::string(std::string name, std::optional<std::string> default_value) {
  return make(std::move(name), ParamType::kString, or_null(default_value));
}
ParamSpec ParamSpec::path(std::string name, std::optional<std::string> default_value) {
  return make(std::move(name), ParamType::kPath, or_null(default_value));
}
ParamSpec ParamSpec::output_path(std::string name, std::optional<std::string> default_value) {
  return make(std::move(name), ParamType::kOutputPath, or_null(default_value));
}
ParamSpec ParamSpec::choice(std::string name, std::vector<std::string> choices,
                            std::string default_value) {
  ParamSpec spec = make(std::move(name), ParamType::kChoice, std::move(default_value));
  spec.choices = std::move(choices);
  return spec;
}
ParamSpec ParamSpec::json(std::string name, nlohmann::json default_value) {
  return make(std::move(name), ParamType::kJson, std::move(default_value));
}

ParamSpec& ParamSpec::range(std::optional<double> minimum, std::optional<double> maximum) {
  min = minimum;
  max = maximum;
  return *this;
}
ParamSpec& ParamSpec::in_unit(std::string unit_name) {
  unit = std::move(unit_name);
  return *this;
}
ParamSpec& ParamSpec::describe(std::string text) {
  description = std::move(text);
  return *this;
}

std::string ParamSpec::check(const nlohmann::json& value) const {
  switch (type) {
    case ParamType::kBool:
      return value.is_boolean() ? "" : "true or false";
    case ParamType::kInteger:
      if (!value.is_number_integer() || !in_range(*this, value.get<double>())) {
        return "an integer" + range_text(*this);
      }
      return "";
    case ParamType::kNumber:
      if (!value.is_number() || !in_range(*this, value.get<double>())) {
        return "a number" + range_text(*this);
      }
      return "";
    case ParamType::kString:
      return value.is_string() ? "" : "a string";
    case ParamType::kPath:
    case ParamType::kOutputPath:
      // An empty path is "none", for a parameter whose default is none.
      return value.is_string() && (!value.get<std::string>().empty() || default_value == "")
                 ? ""
                 : "a file or directory path";
    case ParamType::kChoice:
      if (value.is_string()) {
        for (const auto& choice : choices) {
          if (choice == value.get<std::string>()) return "";
        }
      }
      return "one of " + choices_text(choices);
    case ParamType::kJson:
      return "";
  }
  return "a known parameter type";
}

}  // namespace tilth
