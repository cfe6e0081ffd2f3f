// Fuzz target: the Modbus TCP server's handling of what a client sends. The server is
// only reachable through a socket (its framing, checks and replies live in its poll
// thread), so it runs here as in a graph, on a free loopback port, and each input is
// the byte stream of one client connection: connect, send the input, close the sending
// side, read every reply until the server closes (fuzz/modbus_loopback.h). A bug is a
// crash or sanitizer report in the server thread, a connection the server has not closed
// 5 s after the client's end of stream (a wait that libFuzzer's SIGALRM does not cut
// short), or a reply that is not a whole Modbus TCP frame answering the request at the
// same position (same transaction id and unit, same function code or the exception to
// it).
#include <netinet/in.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "modbus_loopback.h"
#include "tilth/error.h"
#include "tilth/log.h"

namespace {

using tilth::fuzz::half_close_session;
using tilth::fuzz::LoopbackModbusServer;

constexpr std::size_t kMbapSize = 7;
// Within libFuzzer's -timeout (10 s in fuzz/run.sh), so that the target's own report, with
// the connection's TCP state, is the one made.
constexpr std::chrono::milliseconds kCloseTimeout{5000};
constexpr std::size_t kMaxReplyBytes = 1 << 16;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "modbus_request: %s\n", what);
  std::abort();
}

LoopbackModbusServer start_server() {
  // The server logs every client it refuses; the fuzzer's output stays readable.
  tilth::set_log_handler([](tilth::LogLevel, std::string_view, std::string_view) {});
  tilth::modbus::ServerOptions options;
  options.unit_id = 1;
  options.base_register = 100;
  try {
    return LoopbackModbusServer(options);
  } catch (const tilth::Error& error) {
    fail(error.what());
  }
}

std::uint16_t word_at(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
  return static_cast<std::uint16_t>(bytes[offset] << 8 | bytes[offset + 1]);
}

// The whole Modbus TCP frames at the start of `bytes` (by their MBAP length field).
std::vector<std::vector<std::uint8_t>> frames_of(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::vector<std::uint8_t>> frames;
  std::size_t at = 0;
  while (bytes.size() - at >= kMbapSize) {
    const std::size_t length = word_at(bytes, at + 4);
    if (length < 2 || bytes.size() - at < 6 + length) break;
    frames.emplace_back(bytes.begin() + at, bytes.begin() + at + 6 + length);
    at += 6 + length;
  }
  return frames;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const LoopbackModbusServer server = start_server();
  // The client closes first, so each connection leaves a TIME_WAIT (60 s) behind on its
  // side: thousands a second would use up one address's ephemeral ports in seconds. The
  // client therefore connects from the 253 loopback addresses 127.0.0.2 to 127.0.0.254
  // in turn.
  static std::uint32_t connections = 0;
  const std::uint32_t source = INADDR_LOOPBACK + 1 + connections++ % 253;
  tilth::fuzz::HalfCloseOutcome outcome;
  try {
    outcome = half_close_session(source, server.port(), std::span(data, size), kCloseTimeout,
                                 kMaxReplyBytes);
  } catch (const tilth::Error& error) {
    fail(error.what());
  }
  const std::vector<std::uint8_t>& replies = outcome.replies;
  if (replies.size() > kMaxReplyBytes) fail("more reply bytes than requests could ask for");
  if (!outcome.closed) {
    std::fprintf(stderr,
                 "modbus_request: after %zu bytes sent and %zu received, TCP state %u %lld ms "
                 "after the half-close\n",
                 size, replies.size(), outcome.tcp_state,
                 static_cast<long long>(outcome.waited.count()));
    fail("the server kept the connection open");
  }

  const auto requests = frames_of(std::vector<std::uint8_t>(data, data + size));
  const auto answers = frames_of(replies);
  std::size_t answered = 0;
  for (const auto& answer : answers) answered += answer.size();
  if (answered != replies.size()) fail("a reply is not a whole Modbus TCP frame");
  if (answers.size() > requests.size()) fail("more replies than requests");
  for (std::size_t i = 0; i < answers.size(); ++i) {
    const auto& request = requests[i];
    const auto& answer = answers[i];
    if (std::memcmp(answer.data(), request.data(), 4) != 0 || answer[6] != request[6]) {
      fail("a reply's transaction id, protocol id or unit differs from its request's");
    }
    if ((answer[kMbapSize] & 0x7F) != request[kMbapSize]) {
      fail("a reply's function code is neither the request's nor its exception");
    }
  }
  return 0;
}
