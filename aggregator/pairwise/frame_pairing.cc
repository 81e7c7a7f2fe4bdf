#include "aggregator/pairwise/frame_pairing.h"

#include <cmath>

namespace silnet::aggregator {

bool BracketInJ(const SilhouetteSequence& j, uint64_t frame_i, double offset,
                const SilhouetteFrame** a, const SilhouetteFrame** b, double* fraction) {
  const double time = static_cast<double>(frame_i) + offset;
  if (time < 0.0) return false;
  const double floor = std::floor(time);
  const auto index = static_cast<uint64_t>(floor);
  *fraction = time - floor;
  *a = j.Usable(index);
  if (*a == nullptr) return false;
  *b = j.Usable(index + 1);
  if (*fraction < 1e-9) {
    *fraction = 0.0;
    if (*b == nullptr) *b = *a;
    return true;
  }
  return *b != nullptr;
}

int MatchAtFrame(const EpipolarModel& model, const SilhouetteSequence& i,
                 const SilhouetteSequence& j, uint64_t frame_i, TimedMatch out[2], bool with_next) {
  const SilhouetteFrame* fi = i.Usable(frame_i);
  if (fi == nullptr) return 0;
  const SilhouetteFrame *ja = nullptr, *jb = nullptr;
  double fraction = 0.0;
  if (!BracketInJ(j, frame_i, model.offset, &ja, &jb, &fraction)) return 0;
  const OuterTangents ti = ComputeOuterTangents(fi->hull, model.pencil_i.e);
  if (!ti.exists) return 0;
  const OuterTangents ta = ComputeOuterTangents(ja->hull, model.pencil_j.e);
  const bool next = jb != ja && (fraction > 0.0 || with_next);
  const OuterTangents tb = next ? ComputeOuterTangents(jb->hull, model.pencil_j.e) : ta;
  FrontierMatch matches[2];
  const int n = MatchTangents(model, ti, Interpolate(ta, tb, fraction), matches);
  for (int m = 0; m < n; ++m) {
    TimedMatch& t = out[m];
    t.x_i = matches[m].x_i;
    t.frame_i = frame_i;
    t.frame_j = ja->index;
    t.side = matches[m].side;
    t.partner = matches[m].partner;
    t.x_j_a = ta.point[matches[m].partner];
    t.x_j_b = tb.point[matches[m].partner];
  }
  return n;
}

std::vector<TimedMatch> MatchAllFrames(const EpipolarModel& model, const SilhouetteSequence& i,
                                       const SilhouetteSequence& j,
                                       const std::vector<uint64_t>& frames_i) {
  std::vector<TimedMatch> out;
  out.reserve(frames_i.size() * 2);
  TimedMatch matches[2];
  for (uint64_t k : frames_i) {
    const int n = MatchAtFrame(model, i, j, k, matches, true);
    for (int m = 0; m < n; ++m)
      out.push_back(matches[m]);
  }
  return out;
}

std::vector<uint64_t> UsableFrames(const SilhouetteSequence& sequence) {
  std::vector<uint64_t> frames;
  for (const SilhouetteFrame& f : sequence.frames) {
    if (sequence.Usable(f.index) != nullptr) frames.push_back(f.index);
  }
  return frames;
}

}  // namespace silnet::aggregator
