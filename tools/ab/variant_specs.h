// Reads the variants of a comparison from `--variant NAME[:SETTING]` options and from
// a variants file (docs/ab-testing.md). Every problem is reported with where it was
// written and what was expected.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "variant.h"

namespace tilth::ab {

// Adds the variants of a JSON variants file to `variants`. Throws GraphError with
// every problem (file and JSON pointer).
void add_variants_from_file(const std::filesystem::path& file,
                            const std::filesystem::path& default_chain,
                            std::vector<Variant>& variants);

// Applies one `--variant` option: "NAME" declares a variant (the chain as it is);
// "NAME:chain=FILE", "NAME:NODE.type=TYPE" and "NAME:NODE.PARAM=VALUE" declare it if
// needed and change it. Throws tilth::Error naming the option.
void add_variant_option(const std::string& option, const std::filesystem::path& default_chain,
                        std::vector<Variant>& variants);

}  // namespace tilth::ab
