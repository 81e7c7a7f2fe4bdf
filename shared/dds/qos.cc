#include "shared/dds/qos.h"

#include <utility>

namespace silnet::dds {
namespace {

void SetCommon(dds_qos_t* qos, QosProfile profile, const QosSettings& s) {
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, ToDdsDuration(s.max_blocking_time));
  switch (profile) {
    case QosProfile::kFrameStream:
      dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
      dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
      break;
    case QosProfile::kLatched:
      dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
      break;
    case QosProfile::kCommand:
      dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
      dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
      break;
    case QosProfile::kStatus:
      dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
      break;
    case QosProfile::kBulk:
      dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
      dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
      break;
  }
}

}  // namespace

Qos::Qos() : qos_(dds_create_qos()) {}
Qos::~Qos() {
  if (qos_ != nullptr) dds_delete_qos(qos_);
}
Qos::Qos(Qos&& other) noexcept : qos_(std::exchange(other.qos_, nullptr)) {}
Qos& Qos::operator=(Qos&& other) noexcept {
  if (this != &other) {
    if (qos_ != nullptr) dds_delete_qos(qos_);
    qos_ = std::exchange(other.qos_, nullptr);
  }
  return *this;
}

Qos Qos::ForWriter(QosProfile profile, const QosSettings& settings) {
  Qos qos;
  SetCommon(qos.get(), profile, settings);
  if (profile == QosProfile::kFrameStream) {
    // The history a late reader receives: the last frame_history samples per camera.
    dds_qset_durability_service(qos.get(), 0, DDS_HISTORY_KEEP_LAST, settings.frame_history,
                                DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
    dds_qset_resource_limits(qos.get(), DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                             settings.frame_history);
  }
  if (profile == QosProfile::kCommand) {
    dds_qset_lifespan(qos.get(), ToDdsDuration(settings.command_lifespan));
  }
  return qos;
}

Qos Qos::ForReader(QosProfile profile, const QosSettings& settings) {
  Qos qos;
  SetCommon(qos.get(), profile, settings);
  if (profile == QosProfile::kFrameStream || profile == QosProfile::kCommand ||
      profile == QosProfile::kBulk) {
    dds_qset_resource_limits(qos.get(), DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                             settings.reader_limit);
  }
  return qos;
}

}  // namespace silnet::dds
