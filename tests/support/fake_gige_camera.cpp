// tilth-fake-gige-camera ADDRESS SERIAL [--trigger-checks-hz HZ] [--image PNG]: Aravis's
// GigE Vision camera simulator, as arv-fake-gv-camera-0.8 runs it, with two changes a
// test can ask for. --trigger-checks-hz: it looks for a software trigger HZ times a
// second; the stock simulator looks 25 times a second, so its triggered frames leave up
// to 40 ms after their trigger, where a real camera exposes within microseconds.
// --image: it shows that picture (a rendered scene) instead of its moving test pattern,
// with a sensor of the picture's size whose window (Width, Height, OffsetX, OffsetY) and
// pixel format the client sets: a 16-bit PNG as Mono16, an 8-bit grey one as Mono8 or
// as the Bayer mosaic it already is, a colour one as Mono8 or mosaicked to the Bayer
// pattern asked for. Runs until SIGTERM or SIGINT.
//
// Aravis's simulator waits for its next frame, or its next look for a trigger, in g_poll
// with a timeout in whole milliseconds, and spins with a timeout of 0 through the last
// millisecond: looking for a trigger every millisecond, it spins a whole core. A camera
// spends no processor of the host's waiting, so this program's g_poll, which the
// simulator's thread reaches before GLib's, sleeps that last part instead.
#include <poll.h>
#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <arv.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace {

// Set once the simulator runs; its thread is the only one besides main's, which waits
// for a signal.
std::atomic<ArvFakeCamera*> waiting_camera{nullptr};
const pthread_t main_thread = pthread_self();

// The Bayer patterns by the colour of their top-left 2x2 cell, in BGR channel indices.
const std::map<ArvPixelFormat, std::array<int, 4>> kBayerCells = {
    {ARV_PIXEL_FORMAT_BAYER_RG_8, {2, 1, 1, 0}},
    {ARV_PIXEL_FORMAT_BAYER_GR_8, {1, 2, 0, 1}},
    {ARV_PIXEL_FORMAT_BAYER_GB_8, {1, 0, 2, 1}},
    {ARV_PIXEL_FORMAT_BAYER_BG_8, {0, 1, 1, 2}},
};

// The picture as the sensor reads it out in each pixel format, made on first request.
class Scene {
 public:
  explicit Scene(cv::Mat picture) : picture_(std::move(picture)) {}

  int width() const { return picture_.cols; }
  int height() const { return picture_.rows; }

  // Empty when the picture cannot be shown in `format`.
  const cv::Mat& in_format(ArvPixelFormat format) {
    auto [entry, added] = readouts_.try_emplace(format);
    if (added) entry->second = readout(format);
    return entry->second;
  }

 private:
  cv::Mat readout(ArvPixelFormat format) const {
    const int type = picture_.type();
    if (format == ARV_PIXEL_FORMAT_MONO_16) return type == CV_16UC1 ? picture_ : cv::Mat();
    if (format == ARV_PIXEL_FORMAT_MONO_8) {
      if (type == CV_8UC1) return picture_;
      if (type != CV_8UC3) return {};
      cv::Mat gray;
      cv::cvtColor(picture_, gray, cv::COLOR_BGR2GRAY);
      return gray;
    }
    const auto cell = kBayerCells.find(format);
    if (cell == kBayerCells.end()) return {};
    if (type == CV_8UC1) return picture_;
    if (type != CV_8UC3) return {};
    cv::Mat mosaic(picture_.size(), CV_8UC1);
    for (int y = 0; y < picture_.rows; ++y) {
      for (int x = 0; x < picture_.cols; ++x) {
        mosaic.at<std::uint8_t>(y, x) =
            picture_.at<cv::Vec3b>(y, x)[cell->second[2 * (y % 2) + x % 2]];
      }
    }
    return mosaic;
  }

  const cv::Mat picture_;
  std::map<ArvPixelFormat, cv::Mat> readouts_;
};

// ArvFakeCameraFillPattern: the window of the scene the client asked for, black where
// it reaches past the picture.
void show_scene(ArvBuffer* buffer, void* data, guint32, guint32, ArvPixelFormat format) {
  auto& scene = *static_cast<Scene*>(data);
  const cv::Mat& readout = scene.in_format(format);
  const int width = arv_buffer_get_image_width(buffer);
  const int height = arv_buffer_get_image_height(buffer);
  const int x0 = arv_buffer_get_image_x(buffer);
  const int y0 = arv_buffer_get_image_y(buffer);
  const int pixel_bytes = ARV_PIXEL_FORMAT_BIT_PER_PIXEL(format) / 8;
  // The simulator allocated the window's payload; it calls this only when that fits.
  auto* out = static_cast<std::uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, nullptr)));
  const std::size_t row_bytes = static_cast<std::size_t>(width) * pixel_bytes;
  std::memset(out, 0, row_bytes * height);
  if (readout.empty()) {
    static std::once_flag said;
    std::call_once(said, [format] {
      std::fprintf(stderr,
                   "tilth-fake-gige-camera: the image cannot be shown as pixel format "
                   "0x%08x; sending black frames\n",
                   static_cast<unsigned>(format));
    });
    return;
  }
  const int columns = std::max(0, std::min(width, readout.cols - x0));
  for (int y = 0; y < height && y0 + y < readout.rows; ++y) {
    if (columns == 0) break;
    std::memcpy(out + y * row_bytes, readout.ptr(y0 + y) + x0 * pixel_bytes,
                static_cast<std::size_t>(columns) * pixel_bytes);
  }
}

}  // namespace

// GPollFD is struct pollfd on Linux (GLib's g_poll is poll there).
extern "C" gint g_poll(GPollFD* fds, guint nfds, gint timeout) {
  auto* const polled = reinterpret_cast<pollfd*>(fds);
  ArvFakeCamera* const camera = waiting_camera.load();
  if (timeout != 0 || camera == nullptr || pthread_equal(pthread_self(), main_thread)) {
    return poll(polled, nfds, timeout);
  }
  const guint64 wait_us = arv_fake_camera_get_sleep_time_for_next_frame(camera, nullptr);
  const timespec wait{static_cast<time_t>(wait_us / 1000000),
                      static_cast<long>(wait_us % 1000000 * 1000)};
  return ppoll(polled, nfds, &wait, nullptr);
}

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: tilth-fake-gige-camera ADDRESS SERIAL [--trigger-checks-hz HZ] "
               "[--image PNG]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage();
  double checks_hz = 0.0;
  std::string image_path;
  for (int i = 3; i < argc; i += 2) {
    const std::string option = argv[i];
    if (i + 1 >= argc) return usage();
    if (option == "--trigger-checks-hz") {
      checks_hz = std::atof(argv[i + 1]);
      if (checks_hz <= 0.0) {
        std::fprintf(stderr,
                     "tilth-fake-gige-camera: --trigger-checks-hz must be above 0, "
                     "not '%s'\n",
                     argv[i + 1]);
        return 2;
      }
    } else if (option == "--image") {
      image_path = argv[i + 1];
    } else {
      return usage();
    }
  }
  std::unique_ptr<Scene> scene;
  if (!image_path.empty()) {
    cv::Mat picture = cv::imread(image_path, cv::IMREAD_UNCHANGED);
    const int type = picture.type();
    if (picture.empty() || (type != CV_16UC1 && type != CV_8UC1 && type != CV_8UC3)) {
      std::fprintf(stderr,
                   "tilth-fake-gige-camera: --image %s: expected a 16-bit grey, "
                   "8-bit grey or 8-bit colour PNG\n",
                   image_path.c_str());
      return 2;
    }
    scene = std::make_unique<Scene>(std::move(picture));
  }

  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);  // before the simulator's threads

  ArvGvFakeCamera* simulator = arv_gv_fake_camera_new(argv[1], argv[2]);
  if (simulator == nullptr || !arv_gv_fake_camera_is_running(simulator)) {
    std::fprintf(stderr, "tilth-fake-gige-camera: cannot serve a camera on %s\n", argv[1]);
    return 1;
  }
  ArvFakeCamera* camera = arv_gv_fake_camera_get_fake_camera(simulator);
  if (checks_hz > 0.0) arv_fake_camera_set_trigger_frequency(camera, checks_hz);
  waiting_camera = camera;
  if (scene) {
    const auto width = static_cast<guint32>(scene->width());
    const auto height = static_cast<guint32>(scene->height());
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_SENSOR_WIDTH, width);
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_SENSOR_HEIGHT, height);
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_WIDTH, width);
    arv_fake_camera_write_register(camera, ARV_FAKE_CAMERA_REGISTER_HEIGHT, height);
    arv_fake_camera_set_fill_pattern(camera, show_scene, scene.get());
  }
  int signal = 0;
  sigwait(&stop_signals, &signal);
  g_object_unref(simulator);
  return 0;
}
