// Decoding a replayed frame pair's PNGs, the bound of an image-folder replay: one frame
// pair of the simulator's case_e (640x480 16-bit depth, 1280x1024 bgr8 colour), written
// as recording.image_folder writes it (cv::imencode's defaults), decoded
//
//   libdeflate/depth|color   by decode_png, as the recording source does
//   opencv/depth|color       by cv::imdecode (libpng and zlib), as it did before
//
// in ms per image, one thread; MB/s counts the decoded pixels' bytes.
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>

#include "image_folder/png_decoder.h"
#include "simulated_pairs.h"

namespace tilth {
namespace {

const std::string& encoded(const std::string& image) {
  static const auto pngs = [] {
    StageRegistry registry;
    registry.load(TILTH_SYNTHETIC_PLUGIN);
    const testing::SimulatedPair pair = testing::render_pairs(registry, "case_e", 1).front();
    std::vector<std::uint8_t> depth, color;
    cv::imencode(".png", pair.raw->gray, depth);
    cv::imencode(".png", pair.color->pixels, color);
    return std::map<std::string, std::string>{{"depth", {depth.begin(), depth.end()}},
                                              {"color", {color.begin(), color.end()}}};
  }();
  return pngs.at(image);
}

void count(benchmark::State& state, const cv::Mat& decoded, const std::string& png) {
  state.SetBytesProcessed(state.iterations() *
                          static_cast<std::int64_t>(decoded.total() * decoded.elemSize()));
  state.counters["png_MB"] = static_cast<double>(png.size()) / 1e6;
}

void libdeflate(benchmark::State& state, const std::string& image) {
  const std::string& png = encoded(image);
  cv::Mat decoded;
  for (auto _ : state) decoded = *recording::decode_png(png, image + ".png");
  count(state, decoded, png);
}

void opencv(benchmark::State& state, const std::string& image) {
  const std::string& png = encoded(image);
  const cv::Mat bytes(1, static_cast<int>(png.size()), CV_8UC1, const_cast<char*>(png.data()));
  cv::Mat decoded;
  for (auto _ : state) decoded = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  count(state, decoded, png);
}

BENCHMARK_CAPTURE(libdeflate, depth, std::string("depth"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(opencv, depth, std::string("depth"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(libdeflate, color, std::string("color"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(opencv, color, std::string("color"))->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tilth
