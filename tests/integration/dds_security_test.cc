// DDS Security between real processes: a test PKI from scripts/make-test-pki, probes that
// authenticate as the aggregator, a node, an observer, an identity from an untrusted CA, or
// not at all. Valid identities exchange frames; nobody without valid credentials reads or
// publishes silnet topics; a node identity cannot write calibration or commands; a real
// node streams every frame to a real aggregator with both authenticated and encrypted.

#include <gtest/gtest.h>
#include <signal.h>

#include <thread>

#include "shared/io/session_log_reader.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

const std::filesystem::path kBin = SILNET_BINARY_DIR;
const std::filesystem::path kProbe = kBin / "tests/silnet-dds-probe";
const std::filesystem::path kMakePki =
    std::filesystem::path(SILNET_SOURCE_DIR) / "scripts/make-test-pki";
constexpr int kNoReaderOrNoData = 3;
constexpr int kRefusedBySecurity = 6;

class DdsSecurity : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    pki_ = new testing::TempDir();
    testing::ChildProcess make(kMakePki, {(pki_->path() / "pki").string()}, pki_->path());
    ASSERT_EQ(make.Wait(std::chrono::seconds(60)), std::optional<int>(0)) << make.Stderr();
  }
  static void TearDownTestSuite() {
    delete pki_;
    pki_ = nullptr;
  }

  // Environment of a probe that authenticates as `identity`.
  static std::map<std::string, std::string> As(const std::string& identity) {
    return {{"SILNET_DDS_SECURITY", (pki_->path() / "pki").string()},
            {"SILNET_DDS_IDENTITY", identity}};
  }
  // A probe with the given arguments and environment.
  std::unique_ptr<testing::ChildProcess> Probe(const std::vector<std::string>& args,
                                               const std::map<std::string, std::string>& env) {
    return std::make_unique<testing::ChildProcess>(kProbe, args, logs_.path(), env);
  }

  static testing::TempDir* pki_;
  testing::TempDir logs_;
};

testing::TempDir* DdsSecurity::pki_ = nullptr;

TEST_F(DdsSecurity, ANodeAndTheAggregatorExchangeEveryFrame) {
  auto receiver = Probe({"receive", "50", "40"}, As("aggregator"));
  auto publisher = Probe({"publish", "50", "30"}, As("node"));
  ASSERT_EQ(publisher->Wait(std::chrono::seconds(45)), std::optional<int>(0))
      << publisher->Stderr();
  ASSERT_EQ(receiver->Wait(std::chrono::seconds(45)), std::optional<int>(0)) << receiver->Stderr();
  std::istringstream lines(receiver->Stdout());
  uint64_t value = 0, expected = 0;
  while (lines >> value)
    EXPECT_EQ(value, expected++);
  EXPECT_EQ(expected, 50u);
}

TEST_F(DdsSecurity, AParticipantWithoutCredentialsCannotRead) {
  auto receiver = Probe({"receive", "1", "10"}, {});
  auto publisher = Probe({"publish", "5", "8"}, As("node"));
  EXPECT_EQ(publisher->Wait(std::chrono::seconds(20)), std::optional<int>(kNoReaderOrNoData))
      << publisher->Stderr();
  EXPECT_EQ(receiver->Wait(std::chrono::seconds(20)), std::optional<int>(kNoReaderOrNoData));
  EXPECT_EQ(receiver->Stdout(), "");
}

TEST_F(DdsSecurity, AParticipantWithoutCredentialsCannotPublish) {
  auto receiver = Probe({"receive", "1", "10"}, As("aggregator"));
  auto publisher = Probe({"publish", "5", "8"}, {});
  EXPECT_EQ(publisher->Wait(std::chrono::seconds(20)), std::optional<int>(kNoReaderOrNoData));
  EXPECT_EQ(receiver->Wait(std::chrono::seconds(20)), std::optional<int>(kNoReaderOrNoData))
      << receiver->Stderr();
  EXPECT_EQ(receiver->Stdout(), "");
}

TEST_F(DdsSecurity, ACertificateFromAnotherAuthorityIsRefused) {
  auto receiver = Probe({"receive", "1", "10"}, As("rogue"));
  auto publisher = Probe({"publish", "5", "8"}, As("node"));
  EXPECT_EQ(publisher->Wait(std::chrono::seconds(20)), std::optional<int>(kNoReaderOrNoData))
      << publisher->Stderr();
  const auto status = receiver->Wait(std::chrono::seconds(20));
  ASSERT_TRUE(status.has_value());
  EXPECT_NE(*status, 0);
  EXPECT_EQ(receiver->Stdout(), "");
}

TEST_F(DdsSecurity, OnlyTheAggregatorWritesCalibrationAndCommands) {
  for (const std::string topic : {"calibration", "command"}) {
    auto node = Probe({"try-write", topic}, As("node"));
    auto observer = Probe({"try-write", topic}, As("observer"));
    auto aggregator = Probe({"try-write", topic}, As("aggregator"));
    EXPECT_EQ(node->Wait(std::chrono::seconds(20)), std::optional<int>(kRefusedBySecurity))
        << topic << ": " << node->Stderr();
    EXPECT_EQ(observer->Wait(std::chrono::seconds(20)), std::optional<int>(kRefusedBySecurity))
        << topic << ": " << observer->Stderr();
    EXPECT_EQ(aggregator->Wait(std::chrono::seconds(20)), std::optional<int>(0))
        << topic << ": " << aggregator->Stderr();
  }
}

TEST_F(DdsSecurity, AnIncompleteSecuritySetupIsAClearError) {
  auto no_identity =
      Probe({"receive", "1", "1"}, {{"SILNET_DDS_SECURITY", (pki_->path() / "pki").string()}});
  auto unknown = Probe({"receive", "1", "1"}, As("nobody"));
  EXPECT_EQ(no_identity->Wait(std::chrono::seconds(10)), std::optional<int>(1));
  EXPECT_NE(no_identity->Stderr().find("SILNET_DDS_IDENTITY"), std::string::npos);
  EXPECT_EQ(unknown->Wait(std::chrono::seconds(10)), std::optional<int>(1));
  EXPECT_NE(unknown->Stderr().find("nobody/cert.pem is missing"), std::string::npos)
      << unknown->Stderr();
}

TEST_F(DdsSecurity, ARealNodeStreamsEveryFrameToARealAggregator) {
  const std::filesystem::path dataset = logs_ / "dataset";
  testing::ChildProcess sim(kBin / "sim/silnet-sim",
                            {"generate", "-o", dataset.string(), "--cameras", "2", "--frames", "60",
                             "--seed", "5", "--masks-only"},
                            logs_.path());
  ASSERT_EQ(sim.Wait(std::chrono::seconds(120)), std::optional<int>(0)) << sim.Stderr();
  testing::ChildProcess aggregator(kBin / "aggregator/silnet-aggregator",
                                   {"ingest", "-o", (logs_ / "agg").string(), "--idle-exit", "4"},
                                   logs_.path(), As("aggregator"));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  testing::ChildProcess node(
      kBin / "node/silnet-node",
      {"--camera-id", "cam00", "--source", "sim-masks:" + (dataset / "cam00").string(), "--speed",
       "4", "--linger", "3"},
      logs_.path(), As("node"));
  ASSERT_EQ(node.Wait(std::chrono::seconds(60)), std::optional<int>(0)) << node.Stderr();
  ASSERT_EQ(aggregator.Wait(std::chrono::seconds(60)), std::optional<int>(0))
      << aggregator.Stderr();
  const auto sessions = ReadSessionLog(SessionLogPath(logs_ / "agg/sessions", "cam00"));
  ASSERT_EQ(sessions.size(), 1u) << aggregator.Stdout();
  EXPECT_EQ(sessions[0].hulls.size(), 60u);
  EXPECT_NE(aggregator.Stdout().find("0 missing, 0 duplicates, 0 malformed"), std::string::npos)
      << aggregator.Stdout();
}

// Stills on command under DDS Security: real nodes (node identity) answer the aggregator
// identity's `silnet-aggregator stills` with every still, chunks signed and encrypted; the
// same command run with a node identity is refused (a node may not write commands nor read
// stills) with a clear error, and writes nothing.
TEST_F(DdsSecurity, OnlyTheAggregatorCanCommandStills) {
  const std::filesystem::path dataset = logs_ / "dataset";
  testing::ChildProcess sim(kBin / "sim/silnet-sim",
                            {"generate", "-o", dataset.string(), "--cameras", "2", "--frames",
                             "150", "--seed", "6", "--masks-only"},
                            logs_.path());
  ASSERT_EQ(sim.Wait(std::chrono::seconds(120)), std::optional<int>(0)) << sim.Stderr();
  std::vector<std::unique_ptr<testing::ChildProcess>> nodes;
  for (const char* camera : {"cam00", "cam01"}) {
    nodes.push_back(std::make_unique<testing::ChildProcess>(
        kBin / "node/silnet-node",
        std::vector<std::string>{"--camera-id", camera, "--source",
                                 "sim-masks:" + (dataset / camera).string(), "--linger", "60"},
        logs_.path(), As("node")));
  }
  const std::string calibration = (dataset / "ground_truth.yaml").string();
  testing::ChildProcess impostor(kBin / "aggregator/silnet-aggregator",
                                 {"stills", (logs_ / "by-node").string(), "--calib", calibration,
                                  "--timeout", "10", "--discovery", "10"},
                                 logs_.path(), As("node"));
  const std::optional<int> refused = impostor.Wait(std::chrono::seconds(60));
  ASSERT_TRUE(refused.has_value());
  EXPECT_NE(*refused, 0);
  EXPECT_NE(impostor.Stderr().find("DDS"), std::string::npos) << impostor.Stderr();
  EXPECT_FALSE(std::filesystem::exists(logs_ / "by-node" / "stills.yaml"));

  testing::ChildProcess aggregator(kBin / "aggregator/silnet-aggregator",
                                   {"stills", (logs_ / "by-aggregator").string(), "--calib",
                                    calibration, "--timeout", "30", "--discovery", "20"},
                                   logs_.path(), As("aggregator"));
  ASSERT_EQ(aggregator.Wait(std::chrono::seconds(90)), std::optional<int>(0))
      << aggregator.Stdout() << aggregator.Stderr();
  EXPECT_NE(aggregator.Stdout().find("2 of 2 cameras answered"), std::string::npos)
      << aggregator.Stdout();
  for (const char* camera : {"cam00", "cam01"})
    EXPECT_TRUE(std::filesystem::exists(logs_ / "by-aggregator" / camera / "stills/000000.png"));
  for (auto& node : nodes)
    node->Kill(SIGTERM);
}

}  // namespace
}  // namespace silnet
