#include "shared/dds/participant.h"

#include <map>
#include <mutex>

#include "shared/dds/dds_error.h"

namespace silnet::dds {

// An explicitly created Cyclone domain, deleted when the last participant using it goes.
class DomainHandle {
 public:
  DomainHandle(uint32_t id, std::string xml) : xml_(std::move(xml)) {
    entity_ = Entity(
        CheckDds(dds_create_domain(id, xml_.c_str()), "create DDS domain " + std::to_string(id)));
  }
  const std::string& xml() const { return xml_; }

 private:
  std::string xml_;
  Entity entity_;
};

namespace {

std::shared_ptr<DomainHandle> AcquireDomain(const DomainConfig& config) {
  static std::mutex mutex;
  static std::map<uint32_t, std::weak_ptr<DomainHandle>> domains;
  std::lock_guard lock(mutex);
  const std::string xml = config.ToXml();
  if (auto existing = domains[config.domain_id].lock()) {
    if (existing->xml() != xml) {
      throw DdsError("DDS domain " + std::to_string(config.domain_id) +
                         " is already open in this process with a different configuration",
                     DDS_RETCODE_PRECONDITION_NOT_MET);
    }
    return existing;
  }
  auto created = std::make_shared<DomainHandle>(config.domain_id, xml);
  domains[config.domain_id] = created;
  return created;
}

}  // namespace

Participant::Participant(const DomainConfig& config) : config_(config) {
  if (config_.NeedsExplicitDomain()) domain_ = AcquireDomain(config_);
  entity_ = Entity(CheckDds(dds_create_participant(config_.domain_id, nullptr, nullptr),
                            "join DDS " + config_.Describe()));
}

Participant::~Participant() = default;

}  // namespace silnet::dds
