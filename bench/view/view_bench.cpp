// The live view's work per image it sends, in ms: drawing the four panels from a frame
// of the machine's cameras (1280x1024 BayerRG8 colour, 640x480 depth grid) and encoding
// them as JPEG, at the widths a tablet or a desktop would ask for. At view.live's
// default 10 images/s, 1 ms here is 1 % of a core.
#include <memory>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "view_mosaic.h"

namespace tilth::view {
namespace {

// Straw (470 mm, bright) and soil (500 mm, dark) in random 8x8 blocks with noise.
FrameMessages straw_and_soil_frame() {
  cv::RNG random(1);
  const cv::Size grid(640, 480);
  cv::Mat blocks(grid.height / 8, grid.width / 8, CV_8UC1);
  random.fill(blocks, cv::RNG::UNIFORM, 0, 2);
  cv::Mat straw;
  cv::resize(blocks, straw, grid, 0, 0, cv::INTER_NEAREST);

  auto registered = std::make_shared<RegisteredColor>();
  registered->bgr.create(grid, CV_8UC3);
  registered->bgr.setTo(cv::Scalar(55, 80, 110));
  registered->bgr.setTo(cv::Scalar(120, 190, 220), straw);
  cv::Mat noise(grid, CV_8UC3);
  random.fill(noise, cv::RNG::UNIFORM, 0, 24);
  registered->bgr += noise;
  registered->status = cv::Mat::zeros(grid, CV_8UC1);

  auto mask = std::make_shared<ResidueMask>();
  mask->values = straw * 255;

  auto depth = std::make_shared<DepthImage>();
  depth->mm.create(grid, CV_32FC1);
  random.fill(depth->mm, cv::RNG::NORMAL, 500.0, 2.0);
  depth->mm.setTo(470.0, straw);

  auto color = std::make_shared<ColorImage>();
  color->format = PixelFormat::kBayerRggb8;
  color->pixels.create(1024, 1280, CV_8UC1);
  random.fill(color->pixels, cv::RNG::UNIFORM, 40, 220);

  auto distance = std::make_shared<GroundDistance>();
  distance->distance_mm = 500.0;
  distance->valid = true;
  distance->soil_fraction = 0.5;
  return {1, color, registered, mask, depth, distance};
}

cv::Size panel_for(std::int64_t width) {
  return {static_cast<int>(width / 2), static_cast<int>(width / 2 * 3 / 4)};
}

void render(benchmark::State& state) {
  const FrameMessages frame = straw_and_soil_frame();
  const cv::Size panel = panel_for(state.range(0));
  cv::Mat mosaic;
  for (auto _ : state) render_mosaic(frame, panel, cv::Rect(160, 120, 320, 240), mosaic);
}

void encode(benchmark::State& state) {
  cv::Mat mosaic;
  render_mosaic(straw_and_soil_frame(), panel_for(state.range(0)), cv::Rect(160, 120, 320, 240),
                mosaic);
  std::size_t bytes = 0;
  for (auto _ : state) bytes = encode_jpeg(mosaic, 75).size();
  state.counters["kB"] = static_cast<double>(bytes) / 1000.0;
}

BENCHMARK(render)->Arg(640)->Arg(800)->Arg(1280)->Unit(benchmark::kMillisecond);
BENCHMARK(encode)->Arg(640)->Arg(800)->Arg(1280)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tilth::view
