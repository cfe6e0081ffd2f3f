// `tilth cameras`: the GigE Vision cameras this host can reach, and one camera's GenICam
// features. The `tilth` program runs this executable for `tilth cameras ...`.
#include <algorithm>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "aravis/camera_features.h"
#include "aravis/device_list.h"
#include "aravis/gobject_ptr.h"

namespace {

using namespace tilth::aravis;

constexpr const char* kUsage =
    "usage: tilth cameras [--features CAMERA]\n\n"
    "Without options: lists the GigE Vision cameras that answer a discovery on any network\n"
    "interface (vendor, model, serial number, address, device id).\n"
    "  --features CAMERA   every GenICam feature of one camera: name, type, value, access\n"
    "                      (CAMERA: IPv4 address, serial number, device id or MAC address)\n";

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
    return 0;
  }
  std::vector<std::vector<std::string>> rows = {
      {"VENDOR", "MODEL", "SERIAL", "ADDRESS", "DEVICE ID"}};
  for (const auto& device : devices) {
    rows.push_back({device.vendor, device.model, device.serial, device.address, device.id});
  }
  print_table(rows);
  return 0;
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
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 1) return list_cameras();
    if (argc == 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
      std::cout << kUsage;
      return 0;
    }
    if (argc == 3 && std::strcmp(argv[1], "--features") == 0) return dump_features(argv[2]);
    std::cerr << kUsage;
    return 2;
  } catch (const std::exception& error) {
    std::cerr << "tilth cameras: " << error.what() << "\n";
    return 1;
  }
}
