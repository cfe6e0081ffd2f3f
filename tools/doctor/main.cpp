// `tilth doctor` (the tilth-doctor program): checks what makes GigE Vision cameras drop
// frames on Linux, and what else a machine needs, and says how to mend each: one line per
// check, or --json; exit code 0 when nothing failed, 1 otherwise, 2 for bad usage.
#include <iostream>

#include <nlohmann/json.hpp>

#include "camera_checks.h"
#include "command_line.h"
#include "host_checks.h"
#include "tilth/error.h"

namespace {

using namespace tilth::doctor;

constexpr const char* kUsage =
    "usage: tilth doctor [--camera NAME]... [--plc HOST[:PORT]] [--recordings DIR]\n"
    "                    [--min-free-gb N] [--seconds N] [--json]\n\n"
    "Checks the cameras and the host as a machine graph needs them, one line per check\n"
    "(ok, WARN, FAIL) with how to mend it. Exit code 0 when no check failed, 1 otherwise.\n\n"
    "  --camera NAME       a camera to check (address, serial number or device id);\n"
    "                      repeatable; default: every camera that answers a discovery\n"
    "  --plc HOST[:PORT]   the PLC's Modbus TCP server (port 502 by default) must accept\n"
    "                      a connection\n"
    "  --recordings DIR    where recordings and logs go (default: the working directory)\n"
    "  --min-free-gb N     free space wanted there, in GiB (default 10)\n"
    "  --seconds N         how long every camera streams for the loss and clock checks\n"
    "                      (default 3)\n"
    "  --json              the findings as JSON\n";

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;

}  // namespace

int main(int argc, char** argv) {
  try {
    const tilth::cli::CommandLine line(
        argc, argv, 1, {"--camera", "--plc", "--recordings", "--min-free-gb", "--seconds"},
        {"--help", "--json"});
    if (line.flag("--help")) {
      std::cout << kUsage;
      return kExitOk;
    }
    if (!line.positional().empty()) {
      std::cerr << kUsage;
      return kExitUsage;
    }
    const auto seconds = line.count("--seconds", 1, 600).value_or(3);
    const auto min_free_gb = line.count("--min-free-gb", 0, 1'000'000).value_or(10);

    const CameraChecks cameras =
        check_cameras(line.values("--camera"), std::chrono::seconds(seconds));
    std::vector<Finding> findings = cameras.findings;
    findings.push_back(check_receive_buffer_limit(cameras.largest_frame_bytes));
    findings.push_back(check_packet_socket_capability());
    findings.push_back(
        check_free_disk(line.value("--recordings").value_or("."), min_free_gb << 30));
    if (const auto plc = line.value("--plc")) {
      findings.push_back(check_plc(*plc, std::chrono::seconds(2)));
    }

    bool failed = false;
    for (const auto& finding : findings) failed |= finding.verdict == Verdict::kFailed;
    if (line.flag("--json")) {
      nlohmann::json report = {{"ok", !failed}, {"checks", nlohmann::json::array()}};
      for (const auto& finding : findings) {
        report["checks"].push_back({{"check", finding.check},
                                    {"verdict", to_string(finding.verdict)},
                                    {"detail", finding.detail},
                                    {"fix", finding.fix}});
      }
      std::cout << report.dump(2) << "\n";
    } else {
      for (const auto& finding : findings) {
        const std::string_view mark = finding.verdict == Verdict::kOk        ? "ok  "
                                      : finding.verdict == Verdict::kWarning ? "WARN"
                                                                             : "FAIL";
        std::cout << mark << "  " << finding.check << ": " << finding.detail;
        if (!finding.fix.empty()) std::cout << "; fix: " << finding.fix;
        std::cout << "\n";
      }
    }
    return failed ? kExitFailed : kExitOk;
  } catch (const tilth::Error& error) {
    std::cerr << "tilth doctor: " << error.what() << "\n" << kUsage;
    return kExitUsage;
  }
}
