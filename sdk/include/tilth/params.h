// The checked parameter values a stage is made with: every declared parameter is
// present, with its default filled in and relative paths resolved.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace tilth {

class Params {
 public:
  Params() = default;
  explicit Params(nlohmann::json values) : values_(std::move(values)) {}

  bool has(std::string_view name) const;
  bool boolean(std::string_view name) const;
  std::int64_t integer(std::string_view name) const;
  double number(std::string_view name) const;
  std::string string(std::string_view name) const;
  std::filesystem::path path(std::string_view name) const;
  const nlohmann::json& json(std::string_view name) const;

  const nlohmann::json& values() const { return values_; }

 private:
  nlohmann::json values_;  // an object
};

}  // namespace tilth
