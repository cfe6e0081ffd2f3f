// The checks of `tilth doctor` on the host itself: the socket receive buffers GigE Vision
// streams need, the packet-socket capability, free disk for recordings, the PLC reachable.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>

#include "finding.h"

namespace tilth::doctor {

// net.core.rmem_max against the largest frame a camera sends (0: no camera known).
Finding check_receive_buffer_limit(std::uint64_t largest_frame_bytes);

// CAP_NET_RAW, with which Aravis receives streams on a packet socket.
Finding check_packet_socket_capability();

Finding check_free_disk(const std::filesystem::path& directory, std::uint64_t min_free_bytes);

// A TCP connection to the PLC's Modbus server ("HOST" or "HOST:PORT", port 502 by default).
Finding check_plc(const std::string& address, std::chrono::milliseconds timeout);

}  // namespace tilth::doctor
