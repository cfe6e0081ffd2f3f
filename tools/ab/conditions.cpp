#include "conditions.h"

#include <array>
#include <map>
#include <set>

namespace tilth::ab {
namespace {

struct CoverBin {
  double low;  // residue cover = 1 - the truth mask's soil fraction, in [low, high)
  double high;
  const char* label;
};
// Finer towards full cover, where colour rules and depth cues fail first.
constexpr std::array<CoverBin, 5> kCoverBins{{{0.0, 0.25, "0-25 %"},
                                              {0.25, 0.5, "25-50 %"},
                                              {0.5, 0.75, "50-75 %"},
                                              {0.75, 0.9, "75-90 %"},
                                              {0.9, 1.01, "90-100 %"}}};

bool any_frame(const Comparison& comparison, const Condition& condition) {
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      for (const auto& frame : comparison.job(v, r).frames) {
        if (condition.holds(comparison.recordings[r], frame)) return true;
      }
    }
  }
  return false;
}

}  // namespace

std::vector<Condition> conditions_of(const Comparison& comparison) {
  std::vector<Condition> conditions;
  for (const CoverBin& bin : kCoverBins) {
    Condition cover{"residue cover (truth mask)", bin.label,
                    [bin](const Recording&, const FrameResult& frame) {
                      if (!frame.record.truth_soil_fraction) return false;
                      const double cover = 1.0 - *frame.record.truth_soil_fraction;
                      return cover >= bin.low && cover < bin.high;
                    }};
    if (any_frame(comparison, cover)) conditions.push_back(std::move(cover));
  }
  std::map<std::string, std::set<std::string>> tags;
  for (const auto& recording : comparison.recordings) {
    for (const auto& [key, value] : recording.tags) tags[key].insert(value);
  }
  for (const auto& [key, values] : tags) {
    for (const auto& value : values) {
      conditions.push_back(
          {"tag " + key, value, [key, value](const Recording& recording, const FrameResult&) {
             const auto found = recording.tags.find(key);
             return found != recording.tags.end() && found->second == value;
           }});
    }
  }
  return conditions;
}

Comparison restricted_to(const Comparison& comparison, const Condition& condition) {
  Comparison restricted = comparison;
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      auto& frames = restricted.jobs[v * comparison.recordings.size() + r].frames;
      std::erase_if(frames, [&](const FrameResult& frame) {
        return !condition.holds(comparison.recordings[r], frame);
      });
    }
  }
  return restricted;
}

}  // namespace tilth::ab
