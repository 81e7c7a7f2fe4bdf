#include "shared/dds/domain_config.h"

#include <cstdlib>
#include <string_view>

#include "shared/util/check.h"

namespace silnet::dds {
namespace {

const char* GetEnv(const char* name) {
  const char* value = std::getenv(name);
  return (value != nullptr && *value != '\0') ? value : nullptr;
}

bool IsXmlSafe(std::string_view text) {
  for (char c : text) {
    if (c == '<' || c == '>' || c == '&' || c == '"' || c == '\'') return false;
  }
  return true;
}

}  // namespace

DomainConfig DomainConfig::FromEnvironment() {
  DomainConfig config;
  if (const char* id = GetEnv("SILNET_DDS_DOMAIN")) {
    char* end = nullptr;
    const long value = std::strtol(id, &end, 10);
    if (*end != '\0' || value < 0 || value > 232) {
      throw InputError(std::string("SILNET_DDS_DOMAIN must be a domain id 0..232, not '") + id +
                       "'");
    }
    config.domain_id = static_cast<uint32_t>(value);
  }
  if (const char* loopback = GetEnv("SILNET_DDS_LOOPBACK")) {
    const std::string_view v(loopback);
    if (v != "0" && v != "1") throw InputError("SILNET_DDS_LOOPBACK must be 0 or 1");
    config.loopback = v == "1";
  }
  if (const char* tag = GetEnv("SILNET_DDS_TAG")) config.discovery_tag = tag;
  return config;
}

bool DomainConfig::NeedsExplicitDomain() const {
  return loopback || !discovery_tag.empty() || !extra_domain_xml.empty();
}

std::string DomainConfig::ToXml() const {
  if (!IsXmlSafe(discovery_tag)) {
    throw InputError("DDS discovery tag must not contain XML special characters");
  }
  std::string xml = "<CycloneDDS xmlns=\"https://cdds.io/config\"><Domain id=\"any\">";
  if (loopback) {
    xml +=
        "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
        "<AllowMulticast>false</AllowMulticast></General>";
  }
  xml += "<Discovery>";
  if (loopback) {
    xml +=
        "<ParticipantIndex>auto</ParticipantIndex>"
        "<MaxAutoParticipantIndex>100</MaxAutoParticipantIndex>"
        "<Peers><Peer address=\"127.0.0.1\"/></Peers>";
  }
  if (!discovery_tag.empty()) xml += "<Tag>" + discovery_tag + "</Tag>";
  xml += "</Discovery>";
  xml += extra_domain_xml;
  xml += "</Domain></CycloneDDS>";
  return xml;
}

std::string DomainConfig::Describe() const {
  std::string text = "domain " + std::to_string(domain_id);
  text += loopback ? ", loopback" : ", system network";
  if (!discovery_tag.empty()) text += ", tag '" + discovery_tag + "'";
  if (!extra_domain_xml.empty()) text += ", extra configuration";
  return text;
}

}  // namespace silnet::dds
