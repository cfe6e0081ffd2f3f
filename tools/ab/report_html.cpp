#include "report_html.h"

#include <cstdio>

#include "report_assets.h"

namespace tilth::ab {
namespace {

using json = nlohmann::ordered_json;

std::string escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string fixed(const std::optional<double>& value, int decimals = 2) {
  if (!value) return "&ndash;";
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", decimals, *value);
  return text;
}

std::string signed_fixed(const std::optional<double>& value) {
  if (!value) return "&ndash;";
  char text[48];
  std::snprintf(text, sizeof text, "%+.2f", *value);
  return text;
}

std::string cell(const std::string& content, const std::string& css = "") {
  return css.empty() ? "<td>" + content + "</td>"
                     : "<td class=\"" + css + "\">" + content + "</td>";
}

std::optional<double> if_any(const ErrorStats& error, double value) {
  if (error.count == 0) return std::nullopt;
  return value;
}

double ms_per_frame(const std::vector<StageTime>& stages) {
  double total = 0.0;
  for (const auto& stage : stages) total += stage.latency.mean_ms;
  return total;
}

// Fewer frames than this give stage times dominated by the first frames' set-up.
constexpr std::uint64_t kMinFramesToTime = 30;

const char* kFiguresHeader =
    "<th>frames</th><th>frames valid</th><th>frames missed</th><th>frames false valid</th>"
    "<th>frames with an error value</th><th>mean error (mm)</th><th>std of error (mm)</th>"
    "<th>mean |error| (mm)</th><th>max |error| (mm)</th><th>95% CI of mean error (mm)</th>"
    "<th>residue IoU</th><th>residue precision</th><th>residue recall</th>"
    "<th>chain ms / frame</th>";

std::string interval(const std::optional<double>& low, const std::optional<double>& high) {
  if (!low) return "&ndash;";
  return "[" + signed_fixed(low) + ", " + signed_fixed(high) + "]";
}

// Stage times over too few frames say more about set-up than about the stages.
std::string chain_time(const std::vector<StageTime>& stages) {
  if (stages.empty()) return "&ndash;";
  if (stages.front().latency.count < kMinFramesToTime) {
    return "<span title=\"fewer than " + std::to_string(kMinFramesToTime) +
           " frames: not a meaningful time\">(" + fixed(ms_per_frame(stages)) + ")</span>";
  }
  return fixed(ms_per_frame(stages));
}

std::string figure_cells(const Figures& f, const std::vector<StageTime>& stages, bool best) {
  const ErrorStats& e = f.error;
  const auto mask = [&](std::optional<double> (MaskCounts::*ratio)() const) {
    return f.mask ? fixed(((*f.mask).*ratio)(), 3) : std::string("&ndash;");
  };
  return cell(std::to_string(f.frames)) + cell(std::to_string(f.valid)) +
         cell(std::to_string(f.missed), f.missed > 0 ? "bad" : "") +
         cell(std::to_string(f.false_valid), f.false_valid > 0 ? "bad" : "") +
         cell(std::to_string(e.count)) + cell(signed_fixed(if_any(e, e.mean_mm))) +
         cell(fixed(e.std_mm)) + cell(fixed(if_any(e, e.mean_abs_mm)), best ? "best" : "") +
         cell(fixed(if_any(e, e.max_abs_mm))) + cell(interval(e.ci95_low_mm, e.ci95_high_mm)) +
         cell(mask(&MaskCounts::iou)) + cell(mask(&MaskCounts::precision)) +
         cell(mask(&MaskCounts::recall)) + cell(chain_time(stages));
}

// The variant with the smallest mean |error| among those with errors, if any.
std::optional<std::size_t> best_variant(const std::vector<Figures>& figures) {
  std::optional<std::size_t> best;
  for (std::size_t v = 0; v < figures.size(); ++v) {
    if (figures[v].error.count == 0) continue;
    if (!best || figures[v].error.mean_abs_mm < figures[*best].error.mean_abs_mm) best = v;
  }
  return best;
}

std::string variants_section(const Comparison& comparison) {
  std::string html =
      "<h2>Variants</h2>\n<table><tr><th class=\"name\">variant</th><th class=\"name\">chain</th>"
      "<th class=\"name\">changes</th><th class=\"name\">description</th></tr>\n";
  for (const auto& variant : comparison.variants) {
    std::string changes;
    for (const auto& setting : variant.settings) {
      changes +=
          (changes.empty() ? "" : "<br>") +
          escape(setting.node + "." + setting.param + " = " +
                 (setting.command_line_text ? *setting.command_line_text : setting.value.dump()));
    }
    if (variant.recorded) changes = "none: what the machine measured, as recorded";
    html += "<tr>" + cell(escape(variant.name), "name") +
            cell(variant.recorded ? "&ndash;" : escape(variant.chain.string()), "name") +
            cell(changes.empty() ? "(as the chain is)" : changes, "name") +
            cell(escape(variant.description), "name") + "</tr>\n";
  }
  return html + "</table>\n";
}

std::string summary_section(const Comparison& comparison, const ReportFigures& report) {
  std::vector<Figures> figures;
  for (const VariantFigures& variant : report.variants) figures.push_back(variant.figures);
  const auto best = best_variant(figures);
  std::string html = "<h2>All recordings</h2>\n<table><tr><th class=\"name\">variant</th>" +
                     std::string(kFiguresHeader) + "</tr>\n";
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    html += "<tr>" + cell(escape(comparison.variants[v].name), "name") +
            figure_cells(figures[v], comparison.variant_stage_times(v), best == v) + "</tr>\n";
  }
  return html + "</table>\n";
}

std::string verdict_cell(const std::string& verdict) {
  if (verdict == "closer to the truth") return cell(verdict, "name best");
  if (verdict == "farther from the truth") return cell(verdict, "name bad");
  return cell(verdict, "name");
}

std::string count_cell(std::size_t count) {
  return cell(std::to_string(count), count > 0 ? "bad" : "");
}

const char* kPairedHeader =
    "<th>frames with an error value in both</th><th>recordings</th>"
    "<th>mean |error| difference (mm)</th><th>95% CI over recordings (mm)</th>"
    "<th class=\"name\">distance verdict</th><th>frames missed, baseline valid</th>"
    "<th>frames valid, baseline missed</th><th>frames false valid, baseline not</th>"
    "<th>frames not false valid, baseline was</th>";

std::string paired_cells(const VariantFigures& variant) {
  const PairedFigures& p = variant.paired;
  return cell(std::to_string(p.frames_with_both_errors)) + cell(std::to_string(p.recordings)) +
         cell(signed_fixed(p.abs_error_difference_mm)) +
         cell(interval(p.ci95_low_mm, p.ci95_high_mm)) + verdict_cell(variant.verdict) +
         count_cell(p.missed_by_variant_only) + cell(std::to_string(p.missed_by_baseline_only)) +
         count_cell(p.false_valid_by_variant_only) +
         cell(std::to_string(p.false_valid_by_baseline_only));
}

std::string baseline_section(const Comparison& comparison, const ReportFigures& figures) {
  const std::string& baseline = comparison.variants[comparison.baseline].name;
  std::string html =
      "<h2>Against the baseline, " + escape(baseline) +
      "</h2>\n<p class=\"note\">Each variant on the same frames as the baseline: the "
      "difference of |error| (variant &minus; baseline; negative is closer to the truth) "
      "averaged per recording, then over recordings. The 95% interval takes each recording "
      "as one observation (Student's t over the recordings' means), because the frames of "
      "one recording are not independent; it needs two recordings. The verdict is "
      "&ldquo;closer&rdquo; or &ldquo;farther&rdquo; only when the interval excludes "
      "0.</p>\n<table><tr><th class=\"name\">variant</th>" +
      std::string(kPairedHeader) + "</tr>\n";
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    html += "<tr>" + cell(escape(comparison.variants[v].name), "name") +
            paired_cells(figures.variants[v]) + "</tr>\n";
  }
  return html + "</table>\n";
}

std::string conditions_section(const Comparison& comparison, const ReportFigures& figures) {
  if (figures.conditions.empty()) return "";
  std::string html =
      "<h2>By condition</h2>\n<p class=\"note\">The figures of the frames in each "
      "condition: residue cover from the truth mask (1 &minus; its soil fraction), and the "
      "recordings' tags (recording.json, --tags). The comparison with the baseline is made "
      "within the condition.</p>\n<table><tr><th class=\"name\">condition</th>"
      "<th class=\"name\">value</th><th class=\"name\">variant</th><th>frames</th>"
      "<th>frames valid</th><th>frames missed</th><th>frames false valid</th>"
      "<th>mean |error| (mm)</th><th>max |error| (mm)</th><th>residue IoU</th>"
      "<th>mean |error| difference (mm)</th><th>95% CI over recordings (mm)</th>"
      "<th class=\"name\">distance verdict</th></tr>\n";
  for (const ConditionFigures& condition : figures.conditions) {
    for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
      const Figures& f = condition.variants[v].figures;
      const PairedFigures& p = condition.variants[v].paired;
      html += "<tr>" + cell(escape(condition.name), "name") +
              cell(escape(condition.value), "name") +
              cell(escape(comparison.variants[v].name), "name") + cell(std::to_string(f.frames)) +
              cell(std::to_string(f.valid)) + count_cell(f.missed) + count_cell(f.false_valid) +
              cell(fixed(if_any(f.error, f.error.mean_abs_mm))) +
              cell(fixed(if_any(f.error, f.error.max_abs_mm))) +
              cell(f.mask ? fixed(f.mask->iou(), 3) : std::string("&ndash;")) +
              cell(signed_fixed(p.abs_error_difference_mm)) +
              cell(interval(p.ci95_low_mm, p.ci95_high_mm)) +
              verdict_cell(condition.variants[v].verdict) + "</tr>\n";
    }
  }
  return html + "</table>\n";
}

// Who made the report, when and how.
std::string stamp_paragraph(const json& made) {
  const auto line_text = [](const json& line) {
    std::string text;
    for (const auto& argument : line) {
      const std::string word = argument.get<std::string>();
      const bool plain = !word.empty() && word.find_first_of(" \t'\"$\\") == std::string::npos;
      text += (text.empty() ? "" : " ") + (plain ? word : "'" + word + "'");
    }
    return text;
  };
  std::string html = "<p class=\"meta stamp\">tilth " +
                     escape(made["tilth_version"].get<std::string>()) + ", " +
                     escape(made["date_utc"].get<std::string>()) + ", in " +
                     escape(made["working_directory"].get<std::string>()) + ": <code>" +
                     escape(line_text(made["command_line"])) + "</code>";
  for (const auto& shard : made["shard_command_lines"]) {
    html += "<br>shard: <code>" + escape(line_text(shard)) + "</code>";
  }
  return html + "</p>\n";
}

std::string recordings_section(const Comparison& comparison, const ReportFigures& report) {
  std::string html =
      "<h2>Per recording</h2>\n<table><tr><th class=\"name\">recording</th>"
      "<th class=\"name\">variant</th>" +
      std::string(kFiguresHeader) + "</tr>\n";
  for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
    std::vector<Figures> figures;
    for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
      figures.push_back(report.recordings[v][r].figures);
    }
    const auto best = best_variant(figures);
    for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
      const JobResult& job = comparison.job(v, r);
      html += "<tr>" + cell(escape(comparison.recordings[r].name), "name") +
              cell(escape(comparison.variants[v].name) + (job.failed ? " (failed)" : ""),
                   job.failed ? "name bad" : "name") +
              figure_cells(figures[v], job.stages, best == v) + "</tr>\n";
    }
  }
  return html + "</table>\n";
}

std::string stage_times_section(const Comparison& comparison) {
  std::string html =
      "<h2>Time per frame per stage</h2>\n<p class=\"note\">Mean (p99) milliseconds per frame "
      "over every recording, measured while the graphs ran in parallel: compare variants "
      "with each other, not with a machine running one graph. Times over fewer than " +
      std::to_string(kMinFramesToTime) +
      " frames are in parentheses: the first frames' set-up dominates them.</p>\n<table><tr>"
      "<th class=\"name\">variant</th><th class=\"name\">stage</th><th class=\"name\">type</th>"
      "<th>frames</th><th>mean (ms)</th><th>p50 (ms)</th><th>p99 (ms)</th><th>max (ms)</th></tr>\n";
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    for (const auto& stage : comparison.variant_stage_times(v)) {
      const bool few = stage.latency.count < kMinFramesToTime;
      const auto time = [few](double ms) { return few ? "(" + fixed(ms, 3) + ")" : fixed(ms, 3); };
      html += "<tr>" + cell(escape(comparison.variants[v].name), "name") +
              cell(escape(stage.node), "name") + cell(escape(stage.type), "name") +
              cell(std::to_string(stage.latency.count)) + cell(time(stage.latency.mean_ms)) +
              cell(time(stage.latency.p50_ms)) + cell(time(stage.latency.p99_ms)) +
              cell(time(stage.latency.max_ms)) + "</tr>\n";
    }
  }
  return html + "</table>\n";
}

std::string overlays_section(const Comparison& comparison, const Overlays& overlays) {
  std::string html =
      "<h2>Where the variants disagree most</h2>\n<p class=\"note\">Images at the depth "
      "grid's full resolution: click one to zoom (wheel or +/&minus;, Esc closes).</p>\n"
      "<p class=\"key\">"
      "<span><i style=\"background:#ffdc00\"></i>residue, called residue</span>"
      "<span><i style=\"background:#e62828\"></i>soil called residue</span>"
      "<span><i style=\"background:#ff00ff\"></i>residue called soil (reaches the soil "
      "depth; painted over the image)</span>"
      "<span><i style=\"background:#a0a0a0\"></i>unknown</span></p>\n";
  for (std::size_t r = 0; r < overlays.size(); ++r) {
    if (overlays[r].empty()) continue;
    html += "<h3>" + escape(comparison.recordings[r].name) + "</h3>\n";
    for (const auto& frame : overlays[r]) {
      html += "<p>frame " + std::to_string(frame.frame_id) + ": " + escape(frame.reason) +
              "</p>\n<div class=\"overlays\">";
      for (const auto& panel : frame.panels) {
        html += "<figure><figcaption>" + escape(panel.caption) + "</figcaption>";
        html += panel.data_uri.empty()
                    ? "<div class=\"missing\">no image</div>"
                    : "<img alt=\"" + escape(panel.caption) + "\" src=\"" + panel.data_uri + "\">";
        html += "</figure>";
      }
      html += "</div>\n";
    }
  }
  return html;
}

json series_of(const std::vector<FrameResult>& frames, bool truth) {
  json times = json::array();
  json values = json::array();
  for (const auto& frame : frames) {
    times.push_back(frame.time_s);
    const auto& value = truth ? frame.record.truth_mm : frame.record.distance_mm;
    values.push_back(value && (truth || frame.record.valid) ? json(*value) : json());
  }
  return {{"t", times}, {"d", values}};
}

// What the script draws: per recording each variant's distance over time and the truth.
std::string plot_data(const Comparison& comparison, const json& summary) {
  json variants = json::array();
  for (const auto& variant : comparison.variants) variants.push_back(variant.name);
  json recordings = json::array();
  for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
    json series = json::array();
    json truth = {{"t", json::array()}, {"d", json::array()}};
    for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
      const auto& frames = comparison.job(v, r).frames;
      json one = series_of(frames, false);
      one["variant"] = comparison.variants[v].name;
      series.push_back(one);
      if (truth["t"].empty() && !frames.empty()) truth = series_of(frames, true);
    }
    recordings.push_back(
        {{"name", comparison.recordings[r].name}, {"series", series}, {"truth", truth}});
  }
  std::string text = json{{"variants", variants},
                          {"recordings", recordings},
                          {"histogram", summary["error_histogram"]}}
                         .dump();
  // Inside <script>, "</" could end the element early; "<\/" is the same JSON string.
  for (std::size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3)) {
    text.replace(at, 2, "<\\/");
  }
  return text;
}

}  // namespace

std::string report_html(const Comparison& comparison, const ReportFigures& figures,
                        const json& summary, const Overlays& overlays) {
  std::string names;
  for (const auto& variant : comparison.variants) {
    names += (names.empty() ? "" : " vs ") + variant.name;
  }
  char threshold[64];
  std::snprintf(threshold, sizeof threshold, "%.3g", comparison.no_soil_below);
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>tilth ab: " +
      escape(names) + "</title>\n<style>\n" + std::string(kReportCss) + "</style>\n</head>\n" +
      "<body data-rendered=\"no\">\n<h1>tilth ab: " + escape(names) + "</h1>\n" +
      stamp_paragraph(summary["made"]) + "<p class=\"meta\">" +
      std::to_string(comparison.variants.size()) + " variants on " +
      std::to_string(comparison.recordings.size()) +
      " recordings. Error = measured &minus; true distance, over the frames reported valid that "
      "have a true distance. Missed: a true distance with soil in view, reported invalid. False "
      "valid: less than " +
      threshold +
      " of the truth mask is soil, reported valid. Mask figures count pixels, residue being "
      "positive. Every 95% CI is mean &plusmn; t<sub>0.975, n&minus;1</sub>&middot;s/&radic;n. "
      "docs/ab-testing.md defines every figure.</p>\n";
  std::string failures;
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      const JobResult& job = comparison.job(v, r);
      if (job.failed) {
        failures += "<li>" +
                    escape(comparison.variants[v].name + " on " + comparison.recordings[r].name +
                           ": " + job.failure) +
                    "</li>\n";
      }
    }
  }
  if (!failures.empty()) {
    html +=
        "<div class=\"failure\"><b>Some graphs failed; their figures cover the frames "
        "before the failure.</b><ul>\n" +
        failures + "</ul></div>\n";
  }
  html += variants_section(comparison) + summary_section(comparison, figures) +
          baseline_section(comparison, figures) + conditions_section(comparison, figures);
  html +=
      "<h2>Distance over time</h2>\n<p class=\"note\">Lines break at frames reported "
      "invalid, which are also marked by ticks at the bottom.</p>\n";
  for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
    html += "<figure class=\"plot\" data-plot=\"distance\" data-recording=\"" + std::to_string(r) +
            "\"><figcaption>" + escape(comparison.recordings[r].name) + "</figcaption></figure>\n";
  }
  html +=
      "<h2>Distance errors</h2>\n<figure class=\"plot\" data-plot=\"histogram\">"
      "<figcaption>error histogram, every recording</figcaption></figure>\n";
  html += recordings_section(comparison, figures) + stage_times_section(comparison) +
          overlays_section(comparison, overlays);
  html += "<p id=\"render-status\" class=\"note\">plots not drawn (scripts disabled?)</p>\n";
  html += "<script type=\"application/json\" id=\"ab-data\">" + plot_data(comparison, summary) +
          "</script>\n<script>\n" + std::string(kReportJs) + "</script>\n</body>\n</html>\n";
  return html;
}

}  // namespace tilth::ab
