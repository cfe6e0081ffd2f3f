#include "report_numbers.h"

#include <charconv>
#include <ctime>
#include <fstream>

#include "tilth/error.h"
#include "tilth/version.h"

namespace tilth::ab {
namespace {

using json = nlohmann::ordered_json;

constexpr std::size_t kHistogramBins = 30;

json optional_json(const std::optional<double>& value) { return value ? json(*value) : json(); }

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

json error_json(const ErrorStats& error) {
  const auto if_any = [&](double value) { return error.count > 0 ? json(value) : json(); };
  return {{"frames_with_error_value", error.count},
          {"mean_mm", if_any(error.mean_mm)},
          {"std_mm", optional_json(error.std_mm)},
          {"mean_abs_mm", if_any(error.mean_abs_mm)},
          {"max_abs_mm", if_any(error.max_abs_mm)},
          {"rms_mm", if_any(error.rms_mm)},
          {"mean_ci95_low_mm", optional_json(error.ci95_low_mm)},
          {"mean_ci95_high_mm", optional_json(error.ci95_high_mm)}};
}

json figures_json(const Figures& figures) {
  json mask;
  if (figures.mask) {
    const MaskCounts& m = *figures.mask;
    mask = {{"frames_with_both_masks", figures.mask_frames},
            {"px_residue_called_residue", m.tp},
            {"px_soil_called_residue", m.fp},
            {"px_residue_called_soil_or_unknown", m.fn},
            {"px_soil_called_soil_or_unknown", m.tn},
            {"px_called_unknown", m.unknown},
            {"residue_iou", optional_json(m.iou())},
            {"residue_precision", optional_json(m.precision())},
            {"residue_recall", optional_json(m.recall())}};
  }
  return {{"frames", figures.frames},
          {"frames_measured", figures.measured},
          {"frames_valid", figures.valid},
          {"frames_expected_valid", figures.expected_valid},
          {"frames_without_visible_soil", figures.no_visible_soil},
          {"frames_missed", figures.missed},
          {"frames_false_valid", figures.false_valid},
          {"error", error_json(figures.error)},
          {"mask", mask}};
}

json paired_json(const Comparison& comparison, const VariantFigures& figures) {
  const PairedFigures& paired = figures.paired;
  return {{"baseline", comparison.variants[comparison.baseline].name},
          {"frames_with_both_error_values", paired.frames_with_both_errors},
          {"recordings", paired.recordings},
          {"abs_error_difference_mm", optional_json(paired.abs_error_difference_mm)},
          {"abs_error_difference_ci95_low_mm", optional_json(paired.ci95_low_mm)},
          {"abs_error_difference_ci95_high_mm", optional_json(paired.ci95_high_mm)},
          {"verdict", figures.verdict},
          {"frames_missed_by_variant_only", paired.missed_by_variant_only},
          {"frames_missed_by_baseline_only", paired.missed_by_baseline_only},
          {"frames_false_valid_by_variant_only", paired.false_valid_by_variant_only},
          {"frames_false_valid_by_baseline_only", paired.false_valid_by_baseline_only}};
}

json conditions_json(const Comparison& comparison, const ReportFigures& figures) {
  json list = json::array();
  for (const ConditionFigures& condition : figures.conditions) {
    json by_variant = json::array();
    for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
      by_variant.push_back({{"variant", comparison.variants[v].name},
                            {"figures", figures_json(condition.variants[v].figures)},
                            {"against_baseline", paired_json(comparison, condition.variants[v])}});
    }
    list.push_back(
        {{"condition", condition.name}, {"value", condition.value}, {"variants", by_variant}});
  }
  return list;
}

json stamp_json(const ReportStamp& stamp) {
  json shards = json::array();
  for (const auto& line : stamp.shard_command_lines) shards.push_back(line);
  return {{"tilth_version", std::string(version())},
          {"date_utc", utc_now()},
          {"command_line", stamp.command_line},
          {"working_directory", stamp.working_directory.string()},
          {"shard_command_lines", shards}};
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

constexpr const char* kFigureColumns =
    "frames,frames_valid,frames_expected_valid,frames_without_visible_soil,frames_missed,"
    "frames_false_valid,frames_with_error_value,error_mean_mm,error_std_mm,abs_error_mean_mm,"
    "abs_error_max_mm,error_rms_mm,error_mean_ci95_low_mm,error_mean_ci95_high_mm,"
    "frames_with_both_masks,residue_iou,residue_precision,residue_recall,baseline,"
    "frames_with_both_error_values,abs_error_difference_mm,abs_error_difference_ci95_low_mm,"
    "abs_error_difference_ci95_high_mm,verdict,frames_missed_by_variant_only,"
    "frames_missed_by_baseline_only";

// The columns of kFigureColumns, each after a comma.
std::string figure_fields(const Comparison& comparison, const VariantFigures& variant) {
  const Figures& figures = variant.figures;
  const PairedFigures& paired = variant.paired;
  const auto& e = figures.error;
  const auto& m = figures.mask;
  const auto if_any = [&](double value) { return e.count > 0 ? number(value) : ""; };
  std::string row;
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
        csv_field(comparison.variants[comparison.baseline].name),
        std::to_string(paired.frames_with_both_errors), number(paired.abs_error_difference_mm),
        number(paired.ci95_low_mm), number(paired.ci95_high_mm), variant.verdict,
        std::to_string(paired.missed_by_variant_only),
        std::to_string(paired.missed_by_baseline_only)}) {
    row += "," + field;
  }
  return row;
}

std::string summary_row(const Comparison& comparison, std::size_t variant,
                        const std::string& recording, const VariantFigures& figures,
                        const std::vector<StageTime>& stages) {
  double ms_per_frame = 0.0;
  for (const auto& stage : stages) ms_per_frame += stage.latency.mean_ms;
  return csv_field(comparison.variants[variant].name) + "," + csv_field(recording) +
         figure_fields(comparison, figures) + "," + (stages.empty() ? "" : number(ms_per_frame)) +
         "\n";
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
                    {"chain", variant.recorded ? "" : variant.chain.string()},
                    {"settings", settings},
                    {"recorded", variant.recorded}});
  }
  return list;
}

json recordings_json(const std::vector<Recording>& recordings) {
  json list = json::array();
  for (const auto& recording : recordings) {
    list.push_back(
        {{"name", recording.name},
         {"path", recording.path.string()},
         {"format", recording.format == RecordingFormat::kMcap ? "mcap" : "image_folder"},
         {"tags", recording.tags}});
  }
  return list;
}

json summary_json(const Comparison& comparison, const ReportFigures& figures,
                  const Overlays& overlays) {
  const json variants = variants_json(comparison.variants);
  const json recordings = recordings_json(comparison.recordings);
  json by_variant = json::array();
  json by_recording = json::array();
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    by_variant.push_back({{"variant", comparison.variants[v].name},
                          {"figures", figures_json(figures.variants[v].figures)},
                          {"against_baseline", paired_json(comparison, figures.variants[v])},
                          {"stage_times", stage_times_json(comparison.variant_stage_times(v))}});
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      const JobResult& job = comparison.job(v, r);
      by_recording.push_back(
          {{"variant", comparison.variants[v].name},
           {"recording", comparison.recordings[r].name},
           {"failed", job.failed},
           {"failure", job.failure},
           {"figures", figures_json(figures.recordings[v][r].figures)},
           {"against_baseline", paired_json(comparison, figures.recordings[v][r])},
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
  return {{"format", "tilth-ab/2"},
          {"tilth_version", std::string(version())},
          {"made", stamp_json(comparison.stamp)},
          {"no_soil_below", comparison.no_soil_below},
          {"variants", variants},
          {"baseline", comparison.variants[comparison.baseline].name},
          {"recordings", recordings},
          {"variant_figures", by_variant},
          {"recording_figures", by_recording},
          {"conditions", conditions_json(comparison, figures)},
          {"error_histogram", histogram_json(comparison)},
          {"disagreements", disagreements}};
}

void write_summary_csv(const Comparison& comparison, const ReportFigures& figures,
                       const std::filesystem::path& file) {
  std::string text = "variant,recording," + std::string(kFigureColumns) + ",chain_ms_per_frame\n";
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    text += summary_row(comparison, v, "*", figures.variants[v], comparison.variant_stage_times(v));
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      text += summary_row(comparison, v, comparison.recordings[r].name, figures.recordings[v][r],
                          comparison.job(v, r).stages);
    }
  }
  write_text(file, text);
}

void write_conditions_csv(const Comparison& comparison, const ReportFigures& figures,
                          const std::filesystem::path& file) {
  std::string text = "variant,condition,value," + std::string(kFigureColumns) + "\n";
  for (const ConditionFigures& condition : figures.conditions) {
    for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
      text += csv_field(comparison.variants[v].name) + "," + csv_field(condition.name) + "," +
              csv_field(condition.value) + figure_fields(comparison, condition.variants[v]) + "\n";
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
