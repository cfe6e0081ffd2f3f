// A client that sends its requests and half-closes gets its answers and then the
// server's close, whatever other clients do meanwhile and whatever signals arrive; and
// the modbus_request fuzz target (fuzz/modbus_loopback.h) only says "kept open" when
// the server really did keep the connection open.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "modbus_loopback.h"
#include "tilth/log.h"

namespace tilth::fuzz {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

// Reads 2 holding registers at the server's base register 100 (transaction 1, unit 1);
// the answer is 13 bytes.
const Bytes kReadTwoRegisters{0, 1, 0, 0, 0, 6, 1, 3, 0, 100, 0, 2};
constexpr std::size_t kReadTwoRegistersAnswerSize = 13;
constexpr std::size_t kMaxReplyBytes = 1 << 16;

// 127.0.A.B with B = 1..254 by turns: clients that close first leave TIME_WAITs behind,
// spread over many addresses so that no address runs out of ports.
std::uint32_t loopback_address(int a, int turn) {
  return INADDR_LOOPBACK | static_cast<std::uint32_t>(a) << 8 |
         static_cast<std::uint32_t>(1 + turn % 254);
}

// The server logs every client coming and going: the tests keep its errors only (the
// first ten), each of which fails the test.
class ServerLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    previous_ = set_log_handler([this](LogLevel level, std::string_view, std::string_view text) {
      if (level == LogLevel::kError && errors_.size() < 10) errors_.emplace_back(text);
    });
  }
  void TearDown() override {
    set_log_handler(previous_);
    EXPECT_TRUE(errors_.empty()) << "the server logged errors, the first: " << errors_.front();
  }

 private:
  LogHandler previous_;
  std::vector<std::string> errors_;  // written by the server's thread before it is joined
};

// SIGALRM as libFuzzer's -timeout makes it: from an interval timer, to a handler
// installed without SA_RESTART, so that a call waiting in the thread it lands in (the
// main thread, mostly) returns EINTR.
class AlarmSignals {
 public:
  explicit AlarmSignals(std::chrono::microseconds period) {
    struct sigaction action {};
    action.sa_flags = SA_SIGINFO;
    action.sa_sigaction = [](int, siginfo_t*, void*) { delivered_.fetch_add(1); };
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGALRM, &action, &previous_);
    const timeval interval{0, static_cast<suseconds_t>(period.count())};
    const itimerval timer{interval, interval};
    ::setitimer(ITIMER_REAL, &timer, nullptr);
  }
  ~AlarmSignals() {
    const itimerval off{};
    ::setitimer(ITIMER_REAL, &off, nullptr);
    ::sigaction(SIGALRM, &previous_, nullptr);
  }
  AlarmSignals(const AlarmSignals&) = delete;
  AlarmSignals& operator=(const AlarmSignals&) = delete;
  static int delivered() { return delivered_.load(); }

 private:
  static inline std::atomic<int> delivered_{0};
  struct sigaction previous_ {};
};

modbus::ServerOptions fuzz_target_options() {
  modbus::ServerOptions options;
  options.unit_id = 1;
  options.base_register = 100;
  return options;
}

using HalfCloseSessionTest = ServerLogTest;

// libFuzzer's SIGALRM used to end the wait for the server's close early (poll() returned
// -1 with EINTR), and the target reported "the server kept the connection open" at once,
// with the connection in FIN_WAIT1 or FIN_WAIT2 only because the server had not answered
// yet.
TEST_F(HalfCloseSessionTest, ASignalWhileWaitingIsNoConnectionKeptOpen) {
  const LoopbackModbusServer server(fuzz_target_options());
  const AlarmSignals alarms(200us);
  constexpr int kSessions = 2000;
  for (int i = 0; i < kSessions; ++i) {
    const auto outcome = half_close_session(loopback_address(4, i), server.port(),
                                            kReadTwoRegisters, 5s, kMaxReplyBytes);
    ASSERT_TRUE(outcome.closed) << "connection " << i << " reported open " << outcome.waited.count()
                                << " ms after its half-close (TCP state " << outcome.tcp_state
                                << ", " << outcome.replies.size() << " reply bytes), "
                                << AlarmSignals::delivered() << " signals so far";
    ASSERT_EQ(outcome.replies.size(), kReadTwoRegistersAnswerSize) << "connection " << i;
  }
  // Signals did arrive while connections were served.
  EXPECT_GT(AlarmSignals::delivered(), kSessions / 10);
}

// The fuzz target's saved inputs: its seeds and the two after which it reported a
// connection kept open.
std::vector<Bytes> fuzz_inputs() {
  std::vector<Bytes> inputs;
  for (const char* folder : {TILTH_MODBUS_FUZZ_SEEDS, TILTH_MODBUS_FUZZ_REGRESSIONS}) {
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
      std::ifstream file(entry.path(), std::ios::binary);
      inputs.emplace_back(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
    }
  }
  return inputs;
}

// Other clients while the half-closing one comes and goes: the PLC reconnecting (its
// old connection closed to make room), idle clients filling every slot (newcomers
// refused, idle ones closed after idle_timeout), clients leaving with a FIN or an RST,
// some before the server accepted them; so closed descriptors are reused at once.
class Crowd {
 public:
  explicit Crowd(int port) : port_(port), thread_([this] { run(); }) {}
  ~Crowd() {
    stop_ = true;
    thread_.join();
    for (const int fd : open_) ::close(fd);
  }
  Crowd(const Crowd&) = delete;
  Crowd& operator=(const Crowd&) = delete;
  int connections() const { return connections_.load(); }

 private:
  static constexpr std::size_t kOpenAtMost = 6;

  void run() {
    for (int turn = 0; !stop_; ++turn) {
      const bool plc = turn % 5 == 0;
      const int fd = connect_from(plc ? kPlc : loopback_address(5, turn));
      if (fd == -1) continue;
      ++connections_;
      if (turn % 3 == 0) {
        leave(fd, turn);
      } else {
        open_.push_back(fd);
      }
      if (open_.size() > kOpenAtMost) {
        leave(open_.front(), turn);
        open_.pop_front();
      }
      std::this_thread::sleep_for(200us);
    }
  }

  int connect_from(std::uint32_t source) const {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in from{};
    from.sin_family = AF_INET;
    from.sin_addr.s_addr = htonl(source);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port_));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd, reinterpret_cast<const sockaddr*>(&from), sizeof from) != 0 ||
        ::connect(fd, reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0) {
      ::close(fd);
      return -1;
    }
    return fd;
  }

  // With a FIN, or every other time with an RST (SO_LINGER 0).
  static void leave(int fd, int turn) {
    if (turn % 2 == 0) {
      const linger reset{1, 0};
      ::setsockopt(fd, SOL_SOCKET, SO_LINGER, &reset, sizeof reset);
    }
    ::close(fd);
  }

  static constexpr std::uint32_t kPlc = INADDR_LOOPBACK | 1u << 8 | 1u;  // 127.0.1.1
  const int port_;
  std::atomic<bool> stop_{false};
  std::atomic<int> connections_{0};
  std::deque<int> open_;  // the crowd thread's alone
  std::thread thread_;
};

using HalfCloseUnderCrowdTest = ServerLogTest;

TEST_F(HalfCloseUnderCrowdTest, EveryHalfClosedConnectionIsClosedByTheServer) {
  modbus::ServerOptions options = fuzz_target_options();
  options.plc = modbus::Ipv4Ranges::parse("plc_address", "127.0.1.1");
  options.plc_clients = 1;
  options.max_clients = 3;
  options.idle_timeout = 20ms;
  const LoopbackModbusServer server(options);
  const auto inputs = fuzz_inputs();
  ASSERT_FALSE(inputs.empty());
  const Crowd crowd(server.port());
  constexpr int kSessions = 20000;
  int answered = 0;
  for (int i = 0; i < kSessions; ++i) {
    const Bytes& input = inputs[static_cast<std::size_t>(i) % inputs.size()];
    const auto outcome =
        half_close_session(loopback_address(6, i), server.port(), input, 5s, kMaxReplyBytes);
    ASSERT_TRUE(outcome.closed) << "connection " << i << " (input " << i % inputs.size()
                                << ") kept open " << outcome.waited.count()
                                << " ms after its half-close (TCP state " << outcome.tcp_state
                                << ", " << outcome.replies.size() << " reply bytes), "
                                << crowd.connections() << " other connections so far";
    if (!outcome.replies.empty()) ++answered;
  }
  // Both happened: half-closing clients answered, and others all around them.
  EXPECT_GT(answered, kSessions / 10);
  EXPECT_GT(crowd.connections(), 100);
}

}  // namespace
}  // namespace tilth::fuzz
