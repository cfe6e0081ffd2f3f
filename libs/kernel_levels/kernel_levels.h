// Kernels compiled once per instruction-set level (tilth_add_kernel_levels in
// KernelLevels.cmake), and the choice among them when a stage starts: the widest level
// this CPU runs, or one named by hand for comparisons. So one build runs on
// any x86-64 PC and still uses AVX2 where there is one.
#pragma once

#include <cstdlib>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tilth/error.h"

namespace tilth {

// Whether this CPU runs the instruction-set level `level` ("baseline", "x86-64-v3");
// false for names it does not know.
bool cpu_runs_level(std::string_view level);

// Kernels: a struct of one level's functions with `const char* level`, its name.
template <class Kernels>
class KernelLevels {
 public:
  // Every level built, widest first. The environment variable TILTH_KERNEL_LEVEL, when
  // set to a level's name, leaves out the levels wider than it (for comparisons of whole
  // graphs or benchmarks); any other value is an error.
  explicit KernelLevels(std::initializer_list<const Kernels*> built) : built_(built) {
    const char* const widest = std::getenv("TILTH_KERNEL_LEVEL");
    bool allowed = widest == nullptr;
    for (const Kernels* kernels : built_) {
      allowed = allowed || kernels->level == std::string_view(widest);
      if (allowed && cpu_runs_level(kernels->level)) runnable_.push_back(kernels);
    }
    if (!allowed) {
      std::string names;
      for (const Kernels* kernels : built_) names += std::string(", ") + kernels->level;
      throw Error("TILTH_KERNEL_LEVEL is '" + std::string(widest) +
                  "', not a level built: " + names.substr(2));
    }
  }

  // "auto" and the names of the levels built, widest first: a parameter's choices.
  std::vector<std::string> choices() const {
    std::vector<std::string> names = {"auto"};
    for (const Kernels* kernels : built_) names.emplace_back(kernels->level);
    return names;
  }

  // The levels this CPU runs, widest first.
  std::span<const Kernels* const> runnable() const { return runnable_; }

  // The level named `level`, or the widest this CPU runs for "auto". Throws naming the
  // levels this CPU runs when it does not run `level`.
  const Kernels& pick(std::string_view level) const {
    if (level == "auto") return *runnable_.front();
    std::string runs;
    for (const Kernels* kernels : runnable_) {
      if (kernels->level == level) return *kernels;
      runs += std::string(runs.empty() ? "" : ", ") + kernels->level;
    }
    throw Error("this CPU does not run instruction set " + std::string(level) + "; it runs " +
                runs);
  }

 private:
  std::vector<const Kernels*> built_;
  std::vector<const Kernels*> runnable_;
};

}  // namespace tilth

// In a dispatch source, inside the namespace holding the levels' namespaces: declares
// each level's `const Kernels symbol` (defined by the kernel source in its level's
// namespace) and defines `const tilth::KernelLevels<Kernels>& name()`, the levels built,
// widest first.
#ifdef TILTH_KERNEL_LEVELS_X86_64
#define TILTH_KERNEL_LEVELS(Kernels, symbol, name)                                             \
  namespace x86_64_v3 {                                                                        \
  extern const Kernels symbol;                                                                 \
  }                                                                                            \
  namespace baseline {                                                                         \
  extern const Kernels symbol;                                                                 \
  }                                                                                            \
  const ::tilth::KernelLevels<Kernels>& name() {                                               \
    static const ::tilth::KernelLevels<Kernels> levels{&x86_64_v3::symbol, &baseline::symbol}; \
    return levels;                                                                             \
  }
#else
#define TILTH_KERNEL_LEVELS(Kernels, symbol, name)                         \
  namespace baseline {                                                     \
  extern const Kernels symbol;                                             \
  }                                                                        \
  const ::tilth::KernelLevels<Kernels>& name() {                           \
    static const ::tilth::KernelLevels<Kernels> levels{&baseline::symbol}; \
    return levels;                                                         \
  }
#endif
