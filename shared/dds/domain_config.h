#pragma once
// Which DDS domain and network a silnet process joins.
//
// Tests and the demo run every process on one host over loopback unicast, each test in its
// own domain id so `ctest -j` runs do not see each other; a discovery tag separates
// concurrent builds on one machine. Deployments use Cyclone's normal configuration
// (CYCLONEDDS_URI) on a real network.

#include <cstdint>
#include <string>

namespace silnet::dds {

// Domain id and transport settings of a participant.
struct DomainConfig {
  // DDS domain id, 0..232.
  uint32_t domain_id = 0;
  // Restrict Cyclone to 127.0.0.1 unicast with unicast discovery.
  bool loopback = false;
  // Participants whose tags differ ignore each other (empty: no tag).
  std::string discovery_tag;
  // DDS Security: a folder made by scripts/make-test-pki (or laid out alike: identity_ca.pem,
  // permissions_ca.pem, governance.p7s, <identity>/{cert,key,permissions}) and the identity
  // this process authenticates as. Empty folder: no security.
  std::string security_dir;
  std::string security_identity;
  // Extra XML placed inside <Domain>; empty for none.
  std::string extra_domain_xml;

  // Reads SILNET_DDS_DOMAIN (id), SILNET_DDS_LOOPBACK (1/0), SILNET_DDS_TAG,
  // SILNET_DDS_SECURITY (folder) and SILNET_DDS_IDENTITY; unset variables keep the defaults
  // above. Throws InputError on a malformed value, an identity without a security folder (or
  // the reverse), or a security file that is missing.
  static DomainConfig FromEnvironment();

  // True when the domain must be created with an explicit configuration (loopback, tag,
  // security or extra XML); otherwise Cyclone's own configuration (CYCLONEDDS_URI) applies.
  bool NeedsExplicitDomain() const;
  // The Cyclone XML configuration for this domain.
  std::string ToXml() const;
  // One line for logs: "domain 17, loopback, tag 'ci-42'".
  std::string Describe() const;
};

}  // namespace silnet::dds
