#include "report_numbers.h"

#include <charconv>
#include <fstream>

#include "tilth/error.h"
#include "tilth/version.h"

namespace tilth::ab {
namespace {

using json = nlohmann::ordered_json;

constexpr std::size_t kHistogramBins = 30;

json optional_json(const std::optional<double>& value) { return value ? json(*value) : json(); }

json error_json(const ErrorStats& error) {
  return {{"count", error.count},
          {"mean_mm", error.count > 0 ? json(error.mean_mm) : json()},
          {"std_mm", optional_json(error.std_mm)},
          {"mean_abs_mm", error.count > 0 ? json(error.mean_abs_mm) : json()},
          {"max_abs_mm", error.count > 0 ? json(error.max_abs_mm) : json()},
          {"rms_mm", error.count > 0 ? json(error.rms_mm) : json()},
          {"ci95_low_mm", optional_json(error.ci95_low_mm)},
          {"ci95_high_mm", optional_json(error.ci95_high_mm)}};
}

json figures_json(const Figures& figures) {
  json mask;
  if (figures.mask) {
    mask = {{"frames", figures.mask_frames},
            {"tp", figures.mask->tp},
            {"fp", figures.mask->fp},
            {"fn", figures.mask->fn},
            {"tn", figures.mask->tn},
            {"unknown", figures.mask->unknown},
            {"iou", optional_json(figures.mask->iou())},
            {"precision", optional_json(figures.mask->precision())},
            {"recall", optional_json(figures.mask->recall())}};
  }
  return {{"frames", figures.frames},
          {"measured", figures.measured},
          {"valid", figures.valid},
          {"expected_valid", figures.expected_valid},
          {"no_visible_soil", figures.no_visible_soil},
          {"missed", figures.missed},
          {"false_valid", figures.false_valid},
          {"error", error_json(figures.error)},
          {"mask", mask}};
}

std::string setting_text(const NodeSetting& setting) {
  return setting.node + "." + setting.param + "=" +
         (setting.command_line_text ? *setting.command_line_text : setting.value.dump());
}

std::vector<double> errors_of(const Comparison& comparison, std::size_t variant) {
  std::vector<double> errors;
  for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
    for (const auto& frame : comparison.job(variant, r).frames) {
      if (frame.error_mm) errors.push_back(*frame.error_mm);
    }
  }
  return errors;
}

json histogram_json(const Comparison& comparison) {
  std::vector<double> all;
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    const auto errors = errors_of(comparison, v);
    all.insert(all.end(), errors.begin(), errors.end());
  }
  const HistogramBins bins = histogram_bins(all, kHistogramBins);
  json counts = json::object();
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    counts[comparison.variants[v].name] = histogram(bins, errors_of(comparison, v));
  }
  return {{"first_edge_mm", bins.first_edge_mm},
          {"width_mm", bins.width_mm},
          {"bins", bins.count},
          {"counts", counts}};
}

// The shortest text that reads back as the same double; empty for none.
std::string number(const std::optional<double>& value) {
  if (!value) return "";
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, *value).ptr;
  return std::string(text, end);
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string summary_row(const std::string& variant, const std::string& recording,
                        const Figures& figures, const std::vector<StageTime>& stages) {
  double ms_per_frame = 0.0;
  for (const auto& stage : stages) ms_per_frame += stage.latency.mean_ms;
  const auto& e = figures.error;
  const auto& m = figures.mask;
  const auto if_any = [&](double value) { return e.count > 0 ? number(value) : ""; };
  std::string row = csv_field(variant) + "," + csv_field(recording);
  for (const std::size_t count :
       {figures.frames, figures.valid, figures.expected_valid, figures.no_visible_soil,
        figures.missed, figures.false_valid, e.count}) {
    row += "," + std::to_string(count);
  }
  for (const std::string& field :
       {if_any(e.mean_mm), number(e.std_mm), if_any(e.mean_abs_mm), if_any(e.max_abs_mm),
        if_any(e.rms_mm), number(e.ci95_low_mm), number(e.ci95_high_mm),
        std::to_string(figures.mask_frames), m ? number(m->iou()) : "",
        m ? number(m->precision()) : "", m ? number(m->recall()) : "",
        stages.empty() ? "" : number(ms_per_frame)}) {
    row += "," + field;
  }
  return row + "\n";
}

}  // namespace

json stage_times_json(const std::vector<StageTime>& stages) {
  json list = json::array();
  for (const auto& stage : stages) {
    list.push_back({{"node", stage.node},
                    {"type", stage.type},
                    {"frames", stage.latency.count},
                    {"mean_ms", stage.latency.mean_ms},
                    {"p50_ms", stage.latency.p50_ms},
                    {"p99_ms", stage.latency.p99_ms},
                    {"max_ms", stage.latency.max_ms}});
  }
  return list;
}

json variants_json(const std::vector<Variant>& variants) {
  json list = json::array();
  for (const auto& variant : variants) {
    json settings = json::array();
    for (const auto& setting : variant.settings) settings.push_back(setting_text(setting));
    list.push_back({{"name", variant.name},
                    {"description", variant.description},
                    {"chain", variant.chain.string()},
                    {"settings", settings}});
  }
  return list;
}

json recordings_json(const std::vector<Recording>& recordings) {
  json list = json::array();
  for (const auto& recording : recordings) {
    list.push_back(
        {{"name", recording.name},
         {"path", recording.path.string()},
         {"format", recording.format == RecordingFormat::kMcap ? "mcap" : "image_folder"}});
  }
  return list;
}

json summary_json(const Comparison& comparison, const Overlays& overlays) {
  const json variants = variants_json(comparison.variants);
  const json recordings = recordings_json(comparison.recordings);
  json by_variant = json::array();
  json by_recording = json::array();
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    by_variant.push_back({{"variant", comparison.variants[v].name},
                          {"figures", figures_json(comparison.variant_figures(v))},
                          {"stage_times", stage_times_json(comparison.variant_stage_times(v))}});
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      const JobResult& job = comparison.job(v, r);
      by_recording.push_back({{"variant", comparison.variants[v].name},
                              {"recording", comparison.recordings[r].name},
                              {"failed", job.failed},
                              {"failure", job.failure},
                              {"figures", figures_json(comparison.recording_figures(v, r))},
                              {"stage_times", stage_times_json(job.stages)},
                              {"frames_per_second", job.frames_per_second}});
    }
  }
  json disagreements = json::array();
  for (std::size_t r = 0; r < overlays.size(); ++r) {
    json frames = json::array();
    for (const auto& frame : overlays[r]) {
      frames.push_back({{"frame_id", frame.frame_id}, {"reason", frame.reason}});
    }
    disagreements.push_back({{"recording", comparison.recordings[r].name}, {"frames", frames}});
  }
  return {{"format", "tilth-ab/1"},
          {"tilth_version", std::string(version())},
          {"no_soil_below", comparison.no_soil_below},
          {"variants", variants},
          {"recordings", recordings},
          {"variant_figures", by_variant},
          {"recording_figures", by_recording},
          {"error_histogram", histogram_json(comparison)},
          {"disagreements", disagreements}};
}

void write_summary_csv(const Comparison& comparison, const std::filesystem::path& file) {
  std::string text =
      "variant,recording,frames,valid,expected_valid,no_visible_soil,missed,false_valid,"
      "error_count,error_mean_mm,error_std_mm,error_mean_abs_mm,error_max_abs_mm,error_rms_mm,"
      "error_ci95_low_mm,error_ci95_high_mm,mask_frames,mask_iou,mask_precision,mask_recall,"
      "ms_per_frame\n";
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    const std::string& name = comparison.variants[v].name;
    text +=
        summary_row(name, "*", comparison.variant_figures(v), comparison.variant_stage_times(v));
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      text += summary_row(name, comparison.recordings[r].name, comparison.recording_figures(v, r),
                          comparison.job(v, r).stages);
    }
  }
  write_text(file, text);
}

void write_frames_csv(const Comparison& comparison, const std::filesystem::path& file) {
  std::string text =
      "variant,recording,frame_id,time_s,measured,valid,distance_mm,truth_mm,error_mm,expected,"
      "missed,false_valid,truth_soil_fraction,mask_tp,mask_fp,mask_fn,mask_tn,mask_unknown,"
      "invalid_reason\n";
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      for (const auto& frame : comparison.job(v, r).frames) {
        const FrameRecord& record = frame.record;
        const auto count = [&](std::int64_t MaskCounts::*field) {
          return record.mask ? std::to_string((*record.mask).*field) : std::string();
        };
        text += csv_field(comparison.variants[v].name) + "," +
                csv_field(comparison.recordings[r].name) + "," + std::to_string(record.frame_id) +
                "," + number(frame.time_s) + "," + (record.measured ? "1" : "0") + "," +
                (record.valid ? "1" : "0") + "," + number(record.distance_mm) + "," +
                number(record.truth_mm) + "," + number(frame.error_mm) + "," +
                to_string(frame.expected) + "," + (frame.missed ? "1" : "0") + "," +
                (frame.false_valid ? "1" : "0") + "," + number(record.truth_soil_fraction) + "," +
                count(&MaskCounts::tp) + "," + count(&MaskCounts::fp) + "," +
                count(&MaskCounts::fn) + "," + count(&MaskCounts::tn) + "," +
                count(&MaskCounts::unknown) + "," + csv_field(record.invalid_reason) + "\n";
      }
    }
  }
  write_text(file, text);
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out.flush()) throw Error(file.string() + ": cannot write the file");
}

}  // namespace tilth::ab
