// The GigE Vision devices on this host's networks, and which one a stage's `camera`
// parameter (a name, a serial number, an address, or nothing) means.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace tilth::aravis {

struct DeviceEntry {
  std::string id;  // Aravis's device id: "<vendor>-<model>-<serial>" or the user-defined name
  std::string vendor;
  std::string model;
  std::string serial;
  std::string address;      // IPv4
  std::string physical_id;  // MAC address

  // "Aravis Fake (serial TESTA) at 127.0.0.1"
  std::string label() const;
};

// Broadcasts a GigE Vision discovery on every interface and collects the answers
// (about one second).
std::vector<DeviceEntry> discover_devices();

bool is_ipv4_address(std::string_view text);

// The address to open for `name`: an IPv4 address as given (no discovery needed);
// otherwise the address of the discovered device whose id, serial number or MAC address
// is `name`, or of the only device when `name` is empty. Throws tilth::Error listing
// what was found when no device, or more than one, fits.
std::string resolve_camera_address(const std::string& name);

}  // namespace tilth::aravis
