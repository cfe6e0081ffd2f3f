#include "view_server.h"

#include <pthread.h>

#include <chrono>
#include <string>

#include <httplib.h>

#include "tilth/error.h"
#include "view_page.h"

namespace tilth::view {
namespace {

using namespace std::chrono_literals;

// A viewer that asked within this long still counts as watching.
constexpr auto kWatchedFor = 3s;
// How long a request for a newer image waits before it answers 204 No Content.
constexpr auto kImageWait = 2s;
constexpr auto kEventPeriod = 100ms;
constexpr int kStatusEveryEvents = 10;
// Each open page holds about two connections (events and an image request), so this
// many threads serve three or four viewers at once.
constexpr std::size_t kServerThreads = 8;
constexpr const char* kBoundary = "tilthframe";

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string event(const char* name, const nlohmann::json& data) {
  return std::string("event: ") + name + "\ndata: " + data.dump() + "\n\n";
}

std::uint64_t after_param(const httplib::Request& request) {
  if (!request.has_param("after")) return 0;
  try {
    return std::stoull(request.get_param_value("after"));
  } catch (const std::exception&) {
    return 0;
  }
}

}  // namespace

ViewServer::ViewServer(const std::string& host, int port, Content content)
    : content_(std::move(content)), server_(std::make_unique<httplib::Server>()) {
  server_->new_task_queue = [] { return new httplib::ThreadPool(kServerThreads); };
  route();
  port_ = port == 0 ? server_->bind_to_any_port(host) : port;
  if ((port == 0 && port_ < 0) || (port != 0 && !server_->bind_to_port(host, port))) {
    throw Error("the live view cannot listen on " + host + ":" + std::to_string(port) +
                ": the address is in use, not this machine's, or the port needs privileges");
  }
  thread_ = std::thread([this] {
    pthread_setname_np(pthread_self(), "view-listen");
    server_->listen_after_bind();
    listener_returned_.store(true);
  });
  // stop() ends only a server already listening: a run that ends at once must not leave
  // the listener to start after it.
  while (!server_->is_running() && !listener_returned_.load()) {
    std::this_thread::sleep_for(1ms);
  }
  if (!server_->is_running()) {
    thread_.join();
    throw Error("the live view cannot listen on " + host + ":" + std::to_string(port_));
  }
}

ViewServer::~ViewServer() {
  {
    std::lock_guard lock(stop_mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  content_.image->close();
  server_->stop();
  thread_.join();
}

bool ViewServer::watched() const {
  return viewers_.load() > 0 ||
         steady_ns() - last_request_ns_.load() <
             std::chrono::duration_cast<std::chrono::nanoseconds>(kWatchedFor).count();
}

void ViewServer::touch() { last_request_ns_.store(steady_ns()); }

nlohmann::json ViewServer::status() const {
  nlohmann::json status = content_.status();
  status["viewers"] = viewers();
  return status;
}

bool ViewServer::wait_stopping(std::chrono::milliseconds timeout) {
  std::unique_lock lock(stop_mutex_);
  return stop_.wait_for(lock, timeout, [this] { return stopping_; });
}

void ViewServer::route() {
  // Named so that the view's CPU time can be told apart (bench/live_view_cpu.py).
  server_->set_pre_routing_handler([](const httplib::Request&, httplib::Response&) {
    pthread_setname_np(pthread_self(), "view-http");
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server_->Get("/", [](const httplib::Request&, httplib::Response& response) {
    response.set_content(std::string(page_html()), "text/html; charset=utf-8");
  });

  server_->Get("/status.json", [this](const httplib::Request&, httplib::Response& response) {
    response.set_header("Cache-Control", "no-store");
    response.set_content(status().dump(), "application/json");
  });

  // The next image after the one the viewer has: it pulls at its own pace, so a viewer on
  // a slow link gets fewer images, never a backlog.
  server_->Get("/frame.jpg", [this](const httplib::Request& request, httplib::Response& response) {
    touch();
    const LatestImage::Image image = content_.image->newer_than(after_param(request), kImageWait);
    response.set_header("Cache-Control", "no-store");
    if (image.jpeg == nullptr) {
      response.status = 204;
      return;
    }
    response.set_header("X-Generation", std::to_string(image.generation));
    response.set_header("X-Frame-Id", std::to_string(image.frame_id));
    response.set_content(reinterpret_cast<const char*>(image.jpeg->data()), image.jpeg->size(),
                         "image/jpeg");
  });

  // The same images as one MJPEG stream, for players (ffplay, VLC) and <img> tags.
  server_->Get("/stream.mjpg", [this](const httplib::Request&, httplib::Response& response) {
    response.set_header("Cache-Control", "no-store");
    auto generation = std::make_shared<std::uint64_t>(0);
    response.set_content_provider(
        std::string("multipart/x-mixed-replace; boundary=") + kBoundary,
        [this, generation](std::size_t, httplib::DataSink& sink) {
          touch();
          const LatestImage::Image image = content_.image->newer_than(*generation, kImageWait);
          if (wait_stopping(0ms)) return false;
          if (image.jpeg == nullptr) return sink.is_writable();
          *generation = image.generation;
          const std::string head = std::string("--") + kBoundary +
                                   "\r\nContent-Type: image/jpeg\r\nContent-Length: " +
                                   std::to_string(image.jpeg->size()) + "\r\n\r\n";
          return sink.write(head.data(), head.size()) &&
                 sink.write(reinterpret_cast<const char*>(image.jpeg->data()),
                            image.jpeg->size()) &&
                 sink.write("\r\n", 2);
        });
  });

  // The measurements: the history kept on opening, then new samples every 100 ms and the
  // status every second.
  server_->Get("/events", [this](const httplib::Request&, httplib::Response& response) {
    response.set_header("Cache-Control", "no-store");
    struct Stream {
      std::uint64_t sent = 0;
      int ticks = 0;
      bool opened = false;
    };
    auto stream = std::make_shared<Stream>();
    viewers_.fetch_add(1);
    response.set_chunked_content_provider(
        "text/event-stream",
        [this, stream](std::size_t, httplib::DataSink& sink) {
          touch();
          std::string out;
          if (!stream->opened) {
            stream->opened = true;
            out = "retry: 1000\n\n" + event("status", status());
          } else if (wait_stopping(kEventPeriod)) {
            return false;
          }
          if (content_.history->last() > stream->sent) {
            nlohmann::json samples = content_.history->since(stream->sent);
            stream->sent = samples["last"].get<std::uint64_t>();
            out += event("samples", samples);
          }
          if (++stream->ticks % kStatusEveryEvents == 0) out += event("status", status());
          if (out.empty()) out = ": keep-alive\n\n";
          return sink.write(out.data(), out.size());
        },
        [this](bool) { viewers_.fetch_sub(1); });
  });
}

}  // namespace tilth::view
