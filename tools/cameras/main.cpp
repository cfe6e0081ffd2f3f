// `tilth cameras`: the GigE Vision cameras this host can reach, and one camera's GenICam
// features. The `tilth` program runs this executable for `tilth cameras ...`.
#include <algorithm>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "aravis/camera_features.h"
#include "aravis/device_list.h"
#include "aravis/gobject_ptr.h"
#include "command_line.h"
#include "tilth/error.h"

namespace {

using namespace tilth::aravis;

constexpr const char* kUsage =
    "usage: tilth cameras [--features CAMERA]\n\n"
    "Without options: lists the GigE Vision cameras that answer a discovery on any network\n"
    "interface (vendor, model, serial number, address, device id).\n"
    "  --features CAMERA   every GenICam feature of one camera: name, type, value, access\n"
    "                      (CAMERA: IPv4 address, serial number, device id or MAC address)\n";

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;

void print_table(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> widths;
  for (const auto& row : rows) {
    widths.resize(std::max(widths.size(), row.size()));
    for (std::size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], row[c].size());
  }
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t c = 0; c < row.size(); ++c) {
      line += row[c];
      if (c + 1 < row.size()) line += std::string(widths[c] - row[c].size() + 2, ' ');
    }
    std::cout << line << "\n";
  }
}

int list_cameras() {
  const std::vector<DeviceEntry> devices = discover_devices();
  if (devices.empty()) {
    std::cout << "no GigE Vision cameras found\n";
    return kExitOk;
  }
  std::vector<std::vector<std::string>> rows = {
      {"VENDOR", "MODEL", "SERIAL", "ADDRESS", "DEVICE ID"}};
  for (const auto& device : devices) {
    rows.push_back({device.vendor, device.model, device.serial, device.address, device.id});
  }
  print_table(rows);
  return kExitOk;
}

int dump_features(const std::string& name) {
  const std::string address = resolve_camera_address(name);
  GErrorSlot error;
  GObjectPtr<ArvDevice> device(arv_open_device(address.c_str(), error.out()));
  error.check("opening the camera at " + address);
  std::vector<std::vector<std::string>> rows = {{"FEATURE", "TYPE", "VALUE", "ACCESS"}};
  for (const auto& feature : list_features(device.get())) {
    const std::string indented =
        std::string(2 * static_cast<std::size_t>(feature.depth), ' ') + feature.name;
    if (feature.category) {
      rows.push_back({indented, "Category", "", ""});
    } else {
      rows.push_back({indented, feature.type, feature.value, feature.access});
    }
  }
  print_table(rows);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<tilth::cli::CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1, std::set<std::string>{"--features"},
                   std::set<std::string>{"--help"});
  } catch (const tilth::Error& error) {
    std::cerr << "tilth cameras: " << error.what() << "\n" << kUsage;
    return kExitUsage;
  }
  const tilth::cli::CommandLine& line = *parsed;
  if (line.flag("--help")) {
    std::cout << kUsage;
    return kExitOk;
  }
  if (!line.positional().empty()) {
    std::cerr << "tilth cameras: unexpected argument '" << line.positional().front() << "'\n"
              << kUsage;
    return kExitUsage;
  }
  try {
    if (const auto camera = line.value("--features")) return dump_features(*camera);
    return list_cameras();
  } catch (const std::exception& error) {
    std::cerr << "tilth cameras: " << error.what() << "\n";
    return kExitFailed;
  }
}
