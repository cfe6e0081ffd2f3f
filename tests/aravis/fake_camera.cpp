#include "fake_camera.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <vector>

extern char** environ;

namespace tilth::testing {
namespace {

constexpr int kGvcpPort = 3956;

// /proc/net/udp lists a socket bound to address:port as "%08X:%04X" of the address in
// host byte order and the port.
bool udp_port_bound(const std::string& address, int port) {
  in_addr parsed{};
  inet_pton(AF_INET, address.c_str(), &parsed);
  char wanted[32];
  std::snprintf(wanted, sizeof wanted, "%08X:%04X", parsed.s_addr, port);
  std::ifstream table("/proc/net/udp");
  for (std::string line; std::getline(table, line);) {
    if (line.find(wanted) != std::string::npos) return true;
  }
  return false;
}

void ensure_loopback_address(const std::string& address) {
  const std::string command = "ip -o addr show dev lo | grep -q ' inet " + address +
                              "/' || ip addr add " + address + "/8 dev lo";
  if (std::system(command.c_str()) != 0) {
    throw std::runtime_error("cannot add " + address + " to the loopback interface");
  }
}

}  // namespace

FakeCamera::FakeCamera(std::string address, std::string serial, int lost_per_thousand)
    : address_(std::move(address)),
      serial_(std::move(serial)),
      lost_per_thousand_(lost_per_thousand) {
  ensure_loopback_address(address_);
}

FakeCamera::~FakeCamera() { kill(); }

void FakeCamera::start() {
  if (pid_ > 0) return;
  if (udp_port_bound(address_, kGvcpPort)) {
    throw std::runtime_error("another GigE Vision device already listens on " + address_);
  }
  // At a higher priority than the tests: the simulator plays a camera, which has a
  // processor of its own.
  std::vector<std::string> args = {"nice", "-n",     "-10", "arv-fake-gv-camera-0.8",
                                   "-i",   address_, "-s",  serial_};
  if (lost_per_thousand_ > 0) {
    args.insert(args.end(), {"-r", std::to_string(lost_per_thousand_)});
  }
  std::vector<char*> argv;
  for (auto& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t quiet;
  posix_spawn_file_actions_init(&quiet);
  posix_spawn_file_actions_addopen(&quiet, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&quiet, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  const int failed = posix_spawnp(&pid_, argv[0], &quiet, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&quiet);
  if (failed != 0) {
    pid_ = -1;
    throw std::runtime_error("cannot start arv-fake-gv-camera-0.8 (Debian package aravis-tools)");
  }
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!udp_port_bound(address_, kGvcpPort)) {
    if (std::chrono::steady_clock::now() > give_up) {
      throw std::runtime_error("arv-fake-gv-camera-0.8 did not start listening on " + address_);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void FakeCamera::kill() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

}  // namespace tilth::testing
