#include "framework/stage_reference.h"

#include <sstream>

namespace tilth {
namespace {

std::string ports_text(const std::vector<PortSpec>& ports) {
  std::string text;
  for (const auto& port : ports) {
    if (!text.empty()) text += ", ";
    text += port.name + ":" + port.type + (port.required ? "" : "?");
  }
  return text.empty() ? "-" : text;
}

std::string allowed_text(const ParamSpec& spec, std::string_view separator = " | ") {
  std::ostringstream out;
  if (spec.min || spec.max) {
    out << "[";
    spec.min ? out << *spec.min : out << "-inf";
    out << ", ";
    spec.max ? out << *spec.max : out << "inf";
    out << "]";
  }
  for (std::size_t i = 0; i < spec.choices.size(); ++i) {
    out << (i ? separator : "") << spec.choices[i];
  }
  return out.str();
}

std::string default_text(const ParamSpec& spec) {
  return spec.required() ? "(required)" : spec.default_value.dump();
}

}  // namespace

std::string stage_line(const StageRegistry::Entry& entry) {
  const auto& d = entry.descriptor;
  return d.type + "  " + d.summary + "  (in: " + ports_text(d.inputs) +
         "; out: " + ports_text(d.outputs) + ")";
}

std::string stage_reference(const StageRegistry::Entry& entry, bool markdown) {
  const auto& d = entry.descriptor;
  std::ostringstream out;
  const std::string concurrency = d.concurrency == Concurrency::kSerial
                                      ? "serial (stateful, frames in order)"
                                      : "parallel (stateless, frames concurrently)";
  if (markdown) {
    out << "## `" << d.type << "`\n\n" << d.summary << "\n\n";
    out << "Kind: " << to_string(d.kind()) << ", " << concurrency << ". Plugin: `" << entry.plugin
        << "`.\n\n";
    for (const auto* ports : {&d.inputs, &d.outputs}) {
      if (ports->empty()) continue;
      out << (ports == &d.inputs ? "Inputs" : "Outputs") << ":\n\n";
      for (const auto& port : *ports) {
        out << "- `" << port.name << "` (`" << port.type << "`"
            << (port.required ? "" : ", optional") << "): " << port.description << "\n";
      }
      out << "\n";
    }
    if (!d.params.empty()) {
      out << "| parameter | type | default | allowed | unit | description |\n";
      out << "|---|---|---|---|---|---|\n";
      for (const auto& p : d.params) {
        out << "| `" << p.name << "` | " << to_string(p.type) << " | `" << default_text(p) << "` | "
            << allowed_text(p) << " | " << p.unit << " | " << p.description << " |\n";
      }
      out << "\n";
    }
    return out.str();
  }
  out << d.type << ": " << d.summary << "\n";
  out << "  kind: " << to_string(d.kind()) << ", " << concurrency << "\n";
  out << "  plugin: " << entry.plugin << " (" << entry.file.string() << ")\n";
  for (const auto* ports : {&d.inputs, &d.outputs}) {
    out << (ports == &d.inputs ? "  inputs:" : "  outputs:") << (ports->empty() ? " none\n" : "\n");
    for (const auto& port : *ports) {
      out << "    " << port.name << "  " << port.type << (port.required ? "" : " (optional)")
          << "  " << port.description << "\n";
    }
  }
  out << "  parameters:" << (d.params.empty() ? " none\n" : "\n");
  for (const auto& p : d.params) {
    out << "    " << p.name << "  " << to_string(p.type) << ", default " << default_text(p);
    if (const auto allowed = allowed_text(p); !allowed.empty()) out << ", allowed " << allowed;
    if (!p.unit.empty()) out << ", unit " << p.unit;
    out << "\n      " << p.description << "\n";
  }
  return out.str();
}

}  // namespace tilth
