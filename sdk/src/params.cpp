#include "tilth/params.h"

#include "tilth/error.h"

namespace tilth {

bool Params::has(std::string_view name) const {
  return values_.is_object() && values_.contains(name) && !values_.at(std::string(name)).is_null();
}

const nlohmann::json& Params::json(std::string_view name) const {
  if (!values_.is_object() || !values_.contains(name)) {
    throw Error("parameter '" + std::string(name) + "' is not declared by this stage");
  }
  return values_.at(std::string(name));
}

bool Params::boolean(std::string_view name) const { return json(name).get<bool>(); }
std::int64_t Params::integer(std::string_view name) const { return json(name).get<std::int64_t>(); }
double Params::number(std::string_view name) const { return json(name).get<double>(); }
std::string Params::string(std::string_view name) const { return json(name).get<std::string>(); }
std::filesystem::path Params::path(std::string_view name) const {
  return json(name).get<std::string>();
}

}  // namespace tilth
