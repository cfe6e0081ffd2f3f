// One finding of `tilth doctor`: what was checked, how it stands, and how to mend it.
#pragma once

#include <string>
#include <string_view>
#include <utility>

namespace tilth::doctor {

// A failure makes frames drop or the measurement unreachable; a warning costs margin
// (CPU, loss under load) but works.
enum class Verdict { kOk, kWarning, kFailed };

std::string_view to_string(Verdict verdict);

struct Finding {
  Finding() = default;
  explicit Finding(std::string name) : check(std::move(name)) {}
  Finding(std::string name, Verdict how, std::string what, std::string mend)
      : check(std::move(name)), verdict(how), detail(std::move(what)), fix(std::move(mend)) {}

  std::string check;  // "net.core.rmem_max", "camera 10.0.0.11: packet size"
  Verdict verdict = Verdict::kOk;
  std::string detail;  // what was found
  std::string fix;     // how to mend it; empty when ok
};

}  // namespace tilth::doctor
