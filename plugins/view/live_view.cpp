// view.live: a web page to watch while mounting and aiming the cameras (docs/live-view.md).
// The graph hands it each frame's messages; it keeps the measurement for the plot and,
// only while someone watches, at most `fps` times a second and when its renderer thread
// is idle, passes the messages to that thread. It holds one frame's images at most, for
// as long as drawing them takes (a colour image may be a camera's stream buffer). Nothing
// it does waits on the renderer or on a viewer, so the measurement never slows for it.
#include <pthread.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "roi/region_of_interest.h"
#include "tilth/error.h"
#include "tilth/messages/camera_status.h"
#include "tilth/plugin.h"
#include "view_mosaic.h"
#include "view_server.h"

namespace tilth::view {
namespace {

struct ListenAddress {
  std::string host;
  int port = 0;
};

ListenAddress parse_listen(const std::string& value) {
  const auto colon = value.rfind(':');
  const auto bad = [&] {
    return Error("parameter 'listen': \"" + value +
                 "\" is not HOST:PORT (e.g. \"0.0.0.0:8080\", port 0 for any free port)");
  };
  if (colon == std::string::npos || colon == 0 || colon + 1 == value.size()) throw bad();
  const std::string port = value.substr(colon + 1);
  if (port.find_first_not_of("0123456789") != std::string::npos || port.size() > 5) throw bad();
  const int number = std::stoi(port);
  if (number > 65535) throw bad();
  return {value.substr(0, colon), number};
}

double seconds(std::chrono::steady_clock::duration duration) {
  return std::chrono::duration<double>(duration).count();
}

class LiveView final : public Sink {
 public:
  enum Port { kDistance = 0, kColor, kRegistered, kMask, kDepth, kCameras };

  explicit LiveView(const StageContext& context)
      : log_(context.log),
        metrics_(context.pipeline_metrics),
        period_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(1.0 / context.params.number("fps")))),
        width_(static_cast<int>(context.params.integer("width"))),
        quality_(static_cast<int>(context.params.integer("quality"))),
        roi_(context.params.json("roi"), RegionOfInterest::Whole::kMiddleHalf),
        history_(std::chrono::milliseconds(
            static_cast<std::int64_t>(1000.0 * context.params.number("history_s")))) {
    const std::string listen = context.params.string("listen");
    if (listen.empty()) return;
    const ListenAddress address = parse_listen(listen);
    server_.emplace(address.host, address.port,
                    ViewServer::Content{&image_, &history_, [this] { return status(); }});
    // OpenCV lists its codecs on first use, behind a guard ThreadSanitizer cannot see in
    // uninstrumented OpenCV: listed here, before the renderer encodes on its own thread
    // (as recording.image_folder does before its decoding threads).
    cv::haveImageWriter(".jpg");
    renderer_ = std::thread([this] { render_loop(); });
    log_.info("live view at http://" + (address.host == "0.0.0.0" ? "HOST" : address.host) + ":" +
              std::to_string(server_->port()) + "/");
  }

  ~LiveView() override { stop(); }

  void consume(const Frame& frame) override {
    if (!server_) return;
    const auto now = std::chrono::steady_clock::now();
    history_.add(frame.info().frame_id, seconds(now - start_),
                 frame.input<GroundDistance>(kDistance));
    if (!frame.input(kCameras).empty()) {
      std::lock_guard lock(mutex_);
      cameras_ = frame.share_input<CameraStatus>(kCameras);
    }
    if (!server_->watched() || now < next_render_ || drawing_.load()) return;
    // On the period's grid, so that frames a little early or late do not lower the rate.
    next_render_ = std::max(next_render_ + period_, now - period_ / 2);
    FrameMessages messages{frame.info().frame_id,
                           share<ColorImage>(frame, kColor),
                           share<RegisteredColor>(frame, kRegistered),
                           share<ResidueMask>(frame, kMask),
                           share<DepthImage>(frame, kDepth),
                           share<GroundDistance>(frame, kDistance)};
    drawing_.store(true);
    {
      std::lock_guard lock(mutex_);
      pending_ = std::move(messages);
    }
    wake_.notify_one();
  }

  void finish() override { stop(); }

 private:
  template <class T>
  static std::shared_ptr<const T> share(const Frame& frame, Port port) {
    return frame.input(port).empty() ? nullptr : frame.share_input<T>(port);
  }

  void stop() {
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    wake_.notify_one();
    if (renderer_.joinable()) renderer_.join();
    server_.reset();
  }

  void render_loop() {
    pthread_setname_np(pthread_self(), "view-render");
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return done_ || pending_.has_value(); });
      if (done_) return;
      {
        const FrameMessages frame = std::move(*pending_);
        pending_.reset();
        lock.unlock();
        render(frame);
      }  // the frame's images released
      drawing_.store(false);
      lock.lock();
    }
  }

  void render(const FrameMessages& frame) {
    cv::Size grid;
    if (frame.registered)
      grid = frame.registered->bgr.size();
    else if (frame.depth)
      grid = frame.depth->mm.size();
    else if (frame.mask)
      grid = frame.mask->values.size();
    else
      grid = cv::Size(4, 3);
    const cv::Size panel(width_ / 2, std::max(1, width_ / 2 * grid.height / grid.width));
    try {
      const std::optional<cv::Rect> roi =
          grid.width > 4 ? std::optional<cv::Rect>(roi_.on(grid)) : std::nullopt;
      render_mosaic(frame, panel, roi, mosaic_);
      image_.publish(frame.frame_id, encode_jpeg(mosaic_, quality_));
      rendered_.fetch_add(1);
    } catch (const std::exception& failure) {
      if (render_failures_.fetch_add(1) == 0) {
        log_.warning(std::string("live view: frame ") + std::to_string(frame.frame_id) +
                     " could not be drawn (" + failure.what() +
                     "); the measurement goes on, the view shows the last image drawn");
      }
    }
  }

  nlohmann::json status() const {
    const PipelineMetrics metrics = metrics_ ? metrics_() : PipelineMetrics{};
    nlohmann::json stages = nlohmann::json::array();
    for (const StageMetrics& stage : metrics.stages) {
      stages.push_back({{"node", stage.node},
                        {"type", stage.type},
                        {"mean_ms", stage.latency.mean_ms},
                        {"p50_ms", stage.latency.p50_ms},
                        {"p99_ms", stage.latency.p99_ms},
                        {"errors", stage.errors},
                        {"skipped", stage.skipped}});
    }
    nlohmann::json status = {{"frames_completed", metrics.frames_completed},
                             {"frames_dropped", metrics.frames_dropped},
                             {"frames_per_second", metrics.frames_per_second},
                             {"end_to_end_p99_ms", metrics.end_to_end.p99_ms},
                             {"stages", std::move(stages)},
                             {"images_rendered", rendered_.load()},
                             {"cameras", nullptr}};
    std::lock_guard lock(mutex_);
    if (cameras_) {
      status["cameras"] = {{"camera", cameras_->camera},
                           {"streaming", cameras_->streaming},
                           {"problem", cameras_->problem},
                           {"completed", cameras_->completed},
                           {"incomplete", cameras_->incomplete},
                           {"lost", cameras_->lost},
                           {"late", cameras_->late}};
    }
    return status;
  }

  const Logger log_;
  const std::function<PipelineMetrics()> metrics_;
  const std::chrono::steady_clock::duration period_;
  const int width_;
  const int quality_;
  const RegionOfInterest roi_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point next_render_{};
  MeasurementHistory history_;
  LatestImage image_;
  cv::Mat mosaic_;  // the renderer's

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<FrameMessages> pending_;
  std::shared_ptr<const CameraStatus> cameras_;
  bool done_ = false;
  std::atomic<bool> drawing_{false};  // from handing a frame over until its images are released
  std::atomic<std::uint64_t> rendered_{0};
  std::atomic<std::uint64_t> render_failures_{0};

  std::optional<ViewServer> server_;
  std::thread renderer_;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "view.live";
  d.summary =
      "serves a live web page: images with the residue mask, depth, registration, "
      "and the distance over the last minute";
  d.inputs = {
      PortSpec::of<GroundDistance>("distance", "the measurement served"),
      PortSpec::of<ColorImage>("color", "the colour camera's image").optional(),
      PortSpec::of<RegisteredColor>("registered", "colour on the depth grid").optional(),
      PortSpec::of<ResidueMask>("mask", "the residue mask").optional(),
      PortSpec::of<DepthImage>("depth", "depth in mm").optional(),
      PortSpec::of<CameraStatus>("cameras", "the cameras' health").optional(),
  };
  d.params = {
      ParamSpec::string("listen", "")
          .describe("HOST:PORT to serve on (\"0.0.0.0:8080\": every network; port 0: any free "
                    "port); empty: no server, nothing done"),
      ParamSpec::number("fps", 8.0)
          .range(0.5, 30.0)
          .in_unit("1/s")
          .describe("images drawn per second while someone watches"),
      ParamSpec::integer("width", 800)
          .range(320, 2560)
          .in_unit("px")
          .describe("width of the image sent (two panels side by side, two rows)"),
      ParamSpec::integer("quality", 75).range(10, 95).describe("JPEG quality"),
      ParamSpec::number("history_s", 60.0)
          .range(1.0, 3600.0)
          .in_unit("s")
          .describe("how far back the distance plot reaches"),
      roi_param(RegionOfInterest::Whole::kMiddleHalf),
  };
  d.create = factory<LiveView>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::view
