#include "aggregator/calibration/epipolar_consistency.h"

#include <algorithm>

#include "aggregator/pairwise/epipolar_model.h"
#include "aggregator/pairwise/frame_pairing.h"
#include "shared/geometry/epipolar.h"
#include "shared/util/statistics.h"

namespace silnet::aggregator {

const SilhouetteSequence* FindSequence(const std::vector<SilhouetteSequence>& sequences,
                                       const std::string& camera_id) {
  const auto it =
      std::find_if(sequences.begin(), sequences.end(),
                   [&](const SilhouetteSequence& s) { return s.camera_id == camera_id; });
  return it == sequences.end() ? nullptr : &*it;
}

std::vector<PairResidual> MeasureEpipolarResiduals(const std::vector<CameraModel>& cameras,
                                                   const std::vector<bool>& placed,
                                                   const std::vector<SilhouetteSequence>& sequences,
                                                   size_t min_matches) {
  std::vector<PairResidual> out;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const SilhouetteSequence* si = placed[i] ? FindSequence(sequences, cameras[i].id) : nullptr;
    if (si == nullptr || si->frames.empty()) continue;
    const std::vector<uint64_t> frames = UsableFrames(*si);
    const double middle = 0.5 * static_cast<double>(si->first_index() + si->last_index());
    for (size_t j = i + 1; j < cameras.size(); ++j) {
      const SilhouetteSequence* sj = placed[j] ? FindSequence(sequences, cameras[j].id) : nullptr;
      if (sj == nullptr || sj->frames.empty()) continue;
      const PairTiming timing = PairTimingFromCameras(cameras[i], cameras[j]);
      const double offset = timing.offset + (timing.rate - 1.0) * middle;
      const Eigen::Matrix3d f = FundamentalFromCameras(cameras[i], cameras[j]);
      const EpipolarModel model = EpipolarModel::FromFundamental(f, offset);
      std::vector<double> errors;
      for (const TimedMatch& m : MatchAllFrames(model, *si, *sj, frames))
        errors.push_back(TransferError(f, m.x_i, m.XjAt(offset)));
      PairResidual r;
      r.i = i;
      r.j = j;
      r.matches = errors.size();
      if (errors.size() >= min_matches) r.median_px = UpperMedian(std::move(errors));
      out.push_back(r);
    }
  }
  return out;
}

}  // namespace silnet::aggregator
