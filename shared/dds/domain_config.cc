#include "shared/dds/domain_config.h"

#include <cstdlib>
#include <filesystem>
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

// The files of one identity in a security folder, in the order Cyclone's <Security> wants.
struct SecurityFiles {
  std::filesystem::path identity_ca, certificate, private_key, permissions_ca, governance,
      permissions;
};

SecurityFiles LocateSecurityFiles(const std::string& dir, const std::string& identity) {
  const std::filesystem::path root(dir);
  SecurityFiles files{root / "identity_ca.pem",    root / identity / "cert.pem",
                      root / identity / "key.pem", root / "permissions_ca.pem",
                      root / "governance.p7s",     root / identity / "permissions.p7s"};
  for (const auto* file : {&files.identity_ca, &files.certificate, &files.private_key,
                           &files.permissions_ca, &files.governance, &files.permissions}) {
    if (!std::filesystem::is_regular_file(*file)) {
      throw InputError("DDS security file " + file->string() + " is missing (identity '" +
                       identity + "'; make one with scripts/make-test-pki)");
    }
  }
  return files;
}

std::string FileUri(const std::filesystem::path& path) {
  const std::string text = std::filesystem::absolute(path).lexically_normal().string();
  if (!IsXmlSafe(text))
    throw InputError("DDS security path " + text + " has XML special characters");
  return "file:" + text;
}

std::string SecurityXml(const std::string& dir, const std::string& identity) {
  const SecurityFiles f = LocateSecurityFiles(dir, identity);
  return "<Security><Authentication>"
         "<IdentityCA>" +
         FileUri(f.identity_ca) +
         "</IdentityCA>"
         "<IdentityCertificate>" +
         FileUri(f.certificate) +
         "</IdentityCertificate>"
         "<PrivateKey>" +
         FileUri(f.private_key) +
         "</PrivateKey>"
         "</Authentication><AccessControl>"
         "<PermissionsCA>" +
         FileUri(f.permissions_ca) +
         "</PermissionsCA>"
         "<Governance>" +
         FileUri(f.governance) +
         "</Governance>"
         "<Permissions>" +
         FileUri(f.permissions) +
         "</Permissions>"
         "</AccessControl><Cryptographic/></Security>";
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
  if (const char* dir = GetEnv("SILNET_DDS_SECURITY")) config.security_dir = dir;
  if (const char* identity = GetEnv("SILNET_DDS_IDENTITY")) config.security_identity = identity;
  if (config.security_dir.empty() != config.security_identity.empty()) {
    throw InputError(
        "DDS security needs both SILNET_DDS_SECURITY (the PKI folder) and SILNET_DDS_IDENTITY");
  }
  if (!config.security_dir.empty())
    LocateSecurityFiles(config.security_dir, config.security_identity);
  return config;
}

bool DomainConfig::NeedsExplicitDomain() const {
  return loopback || !discovery_tag.empty() || !security_dir.empty() || !extra_domain_xml.empty();
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
  if (!security_dir.empty()) xml += SecurityXml(security_dir, security_identity);
  xml += extra_domain_xml;
  xml += "</Domain></CycloneDDS>";
  return xml;
}

std::string DomainConfig::Describe() const {
  std::string text = "domain " + std::to_string(domain_id);
  text += loopback ? ", loopback" : ", system network";
  if (!discovery_tag.empty()) text += ", tag '" + discovery_tag + "'";
  if (!security_dir.empty()) text += ", secure as '" + security_identity + "'";
  if (!extra_domain_xml.empty()) text += ", extra configuration";
  return text;
}

}  // namespace silnet::dds
