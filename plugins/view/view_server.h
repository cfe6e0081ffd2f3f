// The live view's web server (cpp-httplib): the page, the newest image as a JPEG
// snapshot or an MJPEG stream, the measurements as server-sent events, and the status as
// JSON. It runs on threads of its own and reads only what the stage published, so a
// viewer never slows the measurement.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "latest_image.h"
#include "measurement_history.h"

namespace httplib {
class Server;
}

namespace tilth::view {

class ViewServer {
 public:
  // What it serves: the stage's latest image and history, and its status on demand
  // (called on the server's threads).
  struct Content {
    LatestImage* image;
    const MeasurementHistory* history;
    std::function<nlohmann::json()> status;
  };

  // Listens on `host`:`port` (0: a free port) at once; throws tilth::Error naming the
  // address when it cannot.
  ViewServer(const std::string& host, int port, Content content);
  ~ViewServer();  // closes every connection and joins the server's threads

  int port() const { return port_; }
  // Someone asked for an image or holds the event stream open now or within the last
  // few seconds: only then are images rendered.
  bool watched() const;
  // Event streams open: about one per page open.
  int viewers() const { return viewers_.load(); }

 private:
  void route();
  void touch();
  // The stage's status with the number of viewers.
  nlohmann::json status() const;
  bool wait_stopping(std::chrono::milliseconds timeout);

  Content content_;
  std::unique_ptr<httplib::Server> server_;
  int port_ = 0;
  std::atomic<std::int64_t> last_request_ns_{0};
  std::atomic<int> viewers_{0};
  std::atomic<bool> listener_returned_{false};
  std::mutex stop_mutex_;
  std::condition_variable stop_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace tilth::view
