#pragma once
// Typed DDS topics, writers and readers over the C types idlc generates from idl/silnet.idl.
// A type T is usable once TopicTraits<T> names its descriptor, topic name and QoS profile
// (shared/dds/topics.h).

#include <dds/dds.h>

#include <chrono>
#include <cstdint>
#include <string>

#include "shared/dds/dds_error.h"
#include "shared/dds/entity.h"
#include "shared/dds/participant.h"
#include "shared/dds/qos.h"

namespace silnet::dds {

// Specialised per wire type: descriptor, topic name and QoS profile.
template <class T>
struct TopicTraits;

// A topic of wire type T in a participant.
template <class T>
class Topic {
 public:
  explicit Topic(const Participant& participant)
      : participant_(participant.handle()),
        entity_(CheckDds(dds_create_topic(participant.handle(), TopicTraits<T>::Descriptor(),
                                          TopicTraits<T>::kName, nullptr, nullptr),
                         std::string("create topic ") + TopicTraits<T>::kName)) {}

  dds_entity_t handle() const { return entity_.handle(); }
  dds_entity_t participant() const { return participant_; }
  static const char* name() { return TopicTraits<T>::kName; }

 private:
  dds_entity_t participant_;
  Entity entity_;
};

// Counters a writer's status keeps; totals since the writer was created.
struct WriterCounters {
  uint32_t matched_readers = 0;
  uint32_t offered_deadline_missed = 0;
  uint32_t offered_incompatible_qos = 0;
  uint32_t liveliness_lost = 0;
};

// Publishes samples of T.
template <class T>
class Writer {
 public:
  explicit Writer(const Topic<T>& topic, const QosSettings& settings = {})
      : entity_(CheckDds(
            dds_create_writer(topic.participant(), topic.handle(),
                              Qos::ForWriter(TopicTraits<T>::kProfile, settings).get(), nullptr),
            std::string("create writer for ") + Topic<T>::name())) {}

  // Writes one sample. Returns false if the write timed out under back-pressure
  // (reliable readers not keeping up); throws DdsError on any other failure.
  bool Write(const T& sample) {
    const dds_return_t rc = dds_write(entity_.handle(), &sample);
    if (rc == DDS_RETCODE_TIMEOUT) return false;
    CheckDds(rc, std::string("write to ") + Topic<T>::name());
    return true;
  }

  // Disposes the instance of `key_sample` (readers see it as not alive).
  void Dispose(const T& key_sample) {
    CheckDds(dds_dispose(entity_.handle(), &key_sample),
             std::string("dispose on ") + Topic<T>::name());
  }

  // Blocks until `count` readers matched or `timeout` passed; returns whether they did.
  bool WaitForReaders(uint32_t count, std::chrono::milliseconds timeout) const {
    return WaitForMatch(entity_.handle(), DDS_PUBLICATION_MATCHED_STATUS, count, timeout,
                        [this] { return Counters().matched_readers; });
  }

  // Blocks until every matched reliable reader acknowledged all samples, or timeout.
  bool WaitForAcknowledgements(std::chrono::milliseconds timeout) const {
    const dds_return_t rc = dds_wait_for_acks(
        entity_.handle(),
        ToDdsDuration(std::chrono::duration_cast<std::chrono::nanoseconds>(timeout)));
    if (rc == DDS_RETCODE_TIMEOUT) return false;
    CheckDds(rc, std::string("wait for acknowledgements on ") + Topic<T>::name());
    return true;
  }

  WriterCounters Counters() const {
    WriterCounters c;
    dds_publication_matched_status_t matched{};
    dds_get_publication_matched_status(entity_.handle(), &matched);
    c.matched_readers = matched.current_count;
    dds_offered_deadline_missed_status_t deadline{};
    dds_get_offered_deadline_missed_status(entity_.handle(), &deadline);
    c.offered_deadline_missed = deadline.total_count;
    dds_offered_incompatible_qos_status_t incompatible{};
    dds_get_offered_incompatible_qos_status(entity_.handle(), &incompatible);
    c.offered_incompatible_qos = incompatible.total_count;
    dds_liveliness_lost_status_t liveliness{};
    dds_get_liveliness_lost_status(entity_.handle(), &liveliness);
    c.liveliness_lost = liveliness.total_count;
    return c;
  }

  dds_entity_t handle() const { return entity_.handle(); }

 private:
  template <class CountFn>
  static bool WaitForMatch(dds_entity_t entity, uint32_t status, uint32_t count,
                           std::chrono::milliseconds timeout, CountFn current) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    dds_set_status_mask(entity, status);
    Entity waitset(CheckDds(dds_create_waitset(DDS_CYCLONEDDS_HANDLE), "create waitset"));
    CheckDds(dds_waitset_attach(waitset.handle(), entity, entity), "attach to waitset");
    while (current() < count) {
      const auto left = deadline - std::chrono::steady_clock::now();
      if (left <= std::chrono::nanoseconds::zero()) return false;
      dds_waitset_wait(waitset.handle(), nullptr, 0, ToDdsDuration(left));
    }
    return true;
  }

  Entity entity_;
};

// Counters a reader's status keeps; totals since the reader was created.
struct ReaderCounters {
  uint32_t matched_writers = 0;
  uint32_t samples_lost = 0;
  uint32_t samples_rejected = 0;
  uint32_t requested_deadline_missed = 0;
  uint32_t requested_incompatible_qos = 0;
};

// Receives samples of T. Take() lends samples from Cyclone's cache (no copy); the sample
// reference is valid only inside the callback.
template <class T>
class Reader {
 public:
  explicit Reader(const Topic<T>& topic, const QosSettings& settings = {})
      : entity_(CheckDds(
            dds_create_reader(topic.participant(), topic.handle(),
                              Qos::ForReader(TopicTraits<T>::kProfile, settings).get(), nullptr),
            std::string("create reader for ") + Topic<T>::name())),
        waitset_(CheckDds(dds_create_waitset(DDS_CYCLONEDDS_HANDLE), "create waitset")),
        condition_(CheckDds(dds_create_readcondition(entity_.handle(), DDS_ANY_STATE),
                            "create read condition")) {
    CheckDds(dds_waitset_attach(waitset_.handle(), condition_.handle(), 0),
             "attach read condition");
  }

  // Takes up to `max_samples` samples, calling on_sample(sample, info) for each one that
  // carries data (disposals and unregistrations are skipped). Returns how many it passed on.
  template <class OnSample>
  std::size_t Take(OnSample&& on_sample, std::size_t max_samples = 256) {
    constexpr std::size_t kBatch = 64;
    std::size_t delivered = 0;
    while (delivered < max_samples) {
      void* samples[kBatch] = {};
      dds_sample_info_t infos[kBatch];
      const std::size_t want = std::min(kBatch, max_samples - delivered);
      const int32_t n =
          CheckDds(dds_take(entity_.handle(), samples, infos, want, static_cast<uint32_t>(want)),
                   std::string("take from ") + Topic<T>::name());
      if (n == 0) break;
      LoanGuard guard{entity_.handle(), samples, n};
      for (int32_t i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        on_sample(*static_cast<const T*>(samples[i]), infos[i]);
        ++delivered;
      }
      if (static_cast<std::size_t>(n) < want) break;
    }
    return delivered;
  }

  // Blocks until samples are available or `timeout` passed; returns whether data is there.
  bool WaitForData(std::chrono::milliseconds timeout) {
    const dds_return_t rc = dds_waitset_wait(
        waitset_.handle(), nullptr, 0,
        ToDdsDuration(std::chrono::duration_cast<std::chrono::nanoseconds>(timeout)));
    CheckDds(rc, std::string("wait for data on ") + Topic<T>::name());
    return rc > 0;
  }

  // Blocks until `count` writers matched or `timeout` passed.
  bool WaitForWriters(uint32_t count, std::chrono::milliseconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (Counters().matched_writers < count) {
      if (std::chrono::steady_clock::now() >= deadline) return false;
      dds_sleepfor(DDS_MSECS(5));
    }
    return true;
  }

  ReaderCounters Counters() const {
    ReaderCounters c;
    dds_subscription_matched_status_t matched{};
    dds_get_subscription_matched_status(entity_.handle(), &matched);
    c.matched_writers = matched.current_count;
    dds_sample_lost_status_t lost{};
    dds_get_sample_lost_status(entity_.handle(), &lost);
    c.samples_lost = lost.total_count;
    dds_sample_rejected_status_t rejected{};
    dds_get_sample_rejected_status(entity_.handle(), &rejected);
    c.samples_rejected = rejected.total_count;
    dds_requested_deadline_missed_status_t deadline{};
    dds_get_requested_deadline_missed_status(entity_.handle(), &deadline);
    c.requested_deadline_missed = deadline.total_count;
    dds_requested_incompatible_qos_status_t incompatible{};
    dds_get_requested_incompatible_qos_status(entity_.handle(), &incompatible);
    c.requested_incompatible_qos = incompatible.total_count;
    return c;
  }

  dds_entity_t handle() const { return entity_.handle(); }

 private:
  // Returns a loan on scope exit, also when the callback throws.
  struct LoanGuard {
    dds_entity_t reader;
    void** samples;
    int32_t count;
    ~LoanGuard() { dds_return_loan(reader, samples, count); }
  };

  Entity entity_;
  Entity waitset_;
  Entity condition_;
};

}  // namespace silnet::dds
