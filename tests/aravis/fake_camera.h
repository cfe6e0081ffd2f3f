// Aravis's GigE Vision camera simulator (arv-fake-gv-camera-0.8) as a child process on
// a loopback address of its own, for tests: started, killed mid-stream, started again.
#pragma once

#include <sys/types.h>

#include <string>

namespace tilth::testing {

class FakeCamera {
 public:
  // `address` is added to the loopback interface when missing (tests run as root).
  // lost_per_thousand: stream packets the simulator drops on purpose (its -r option).
  FakeCamera(std::string address, std::string serial, int lost_per_thousand = 0);
  ~FakeCamera();
  FakeCamera(const FakeCamera&) = delete;
  FakeCamera& operator=(const FakeCamera&) = delete;

  // Starts the simulator and waits until it listens for GigE Vision control packets.
  void start();
  // SIGKILL: the camera vanishes without a word, as when its cable is pulled.
  void kill();

  const std::string& address() const { return address_; }
  const std::string& serial() const { return serial_; }

 private:
  const std::string address_;
  const std::string serial_;
  const int lost_per_thousand_;
  pid_t pid_ = -1;
};

}  // namespace tilth::testing
