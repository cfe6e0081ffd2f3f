#include "aravis/device_list.h"

#include <arpa/inet.h>

#include <arv.h>

#include "tilth/error.h"

namespace tilth::aravis {
namespace {

std::string text_or_empty(const char* text) { return text != nullptr ? text : ""; }

std::string listing(const std::vector<DeviceEntry>& devices) {
  std::string text;
  for (const auto& device : devices) text += (text.empty() ? "" : "; ") + device.label();
  return text;
}

}  // namespace

std::string DeviceEntry::label() const {
  return vendor + " " + model + " (serial " + serial + ") at " + address;
}

std::vector<DeviceEntry> discover_devices() {
  arv_update_device_list();
  std::vector<DeviceEntry> devices;
  for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
    if (text_or_empty(arv_get_device_protocol(i)) != "GigEVision") continue;
    devices.push_back(
        {text_or_empty(arv_get_device_id(i)), text_or_empty(arv_get_device_vendor(i)),
         text_or_empty(arv_get_device_model(i)), text_or_empty(arv_get_device_serial_nbr(i)),
         text_or_empty(arv_get_device_address(i)), text_or_empty(arv_get_device_physical_id(i))});
  }
  return devices;
}

bool is_ipv4_address(std::string_view text) {
  in_addr address{};
  return inet_pton(AF_INET, std::string(text).c_str(), &address) == 1;
}

std::string resolve_camera_address(const std::string& name) {
  if (is_ipv4_address(name)) return name;
  const std::vector<DeviceEntry> devices = discover_devices();
  if (name.empty()) {
    if (devices.size() == 1) return devices.front().address;
    if (devices.empty()) throw Error("no GigE Vision camera found on any network interface");
    throw Error(std::to_string(devices.size()) + " GigE Vision cameras found (" + listing(devices) +
                "); name one with the 'camera' parameter (serial number, device id or address)");
  }
  std::vector<DeviceEntry> matching;
  for (const auto& device : devices) {
    if (device.id == name || device.serial == name || device.physical_id == name) {
      matching.push_back(device);
    }
  }
  if (matching.size() == 1) return matching.front().address;
  if (matching.empty()) {
    throw Error("no GigE Vision camera with device id, serial number or MAC address '" + name +
                "' (found: " + (devices.empty() ? "none" : listing(devices)) + ")");
  }
  throw Error("several GigE Vision cameras match '" + name + "' (" + listing(matching) +
              "); name one by its address");
}

}  // namespace tilth::aravis
