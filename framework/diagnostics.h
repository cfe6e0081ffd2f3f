// Problems found in a graph, all collected before any is reported, each with where it
// is and what was expected.
#pragma once

#include <string>
#include <vector>

#include "framework/location.h"
#include "tilth/error.h"

namespace tilth {

struct Diagnostic {
  Location where;
  std::string message;

  std::string text() const { return where.text() + ": " + message; }
};

class Diagnostics {
 public:
  void add(Location where, std::string message);
  bool empty() const { return items_.empty(); }
  const std::vector<Diagnostic>& items() const { return items_; }
  // One problem per line.
  std::string text() const;
  // Throws GraphError when there is anything to report.
  void throw_if_any() const;

 private:
  std::vector<Diagnostic> items_;
};

class GraphError : public Error {
 public:
  explicit GraphError(Diagnostics diagnostics)
      : Error(diagnostics.text()), diagnostics_(std::move(diagnostics)) {}
  const Diagnostics& diagnostics() const { return diagnostics_; }

 private:
  Diagnostics diagnostics_;
};

}  // namespace tilth
