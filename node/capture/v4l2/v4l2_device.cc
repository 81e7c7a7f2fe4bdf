#include "node/capture/v4l2/v4l2_device.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>

namespace silnet::node {
namespace {

// V4l2Device over the kernel's system calls.
class SystemV4l2Device : public V4l2Device {
 public:
  int Open(const std::string& path, int flags) override {
    int fd = -1;
    do {
      fd = ::open(path.c_str(), flags);
    } while (fd < 0 && errno == EINTR);
    return fd;
  }

  // Linux releases the descriptor even when close() is interrupted, so it is never retried.
  int Close(int fd) override { return ::close(fd); }

  int Ioctl(int fd, unsigned long request, void* arg) override {
    int result = -1;
    do {
      result = ::ioctl(fd, request, arg);
    } while (result < 0 && errno == EINTR);
    return result;
  }

  void* Mmap(size_t length, int fd, off_t offset) override {
    return ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
  }

  int Munmap(void* address, size_t length) override { return ::munmap(address, length); }

  int Poll(int fd, int timeout_ms) override {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
    int wait_ms = timeout_ms;
    while (true) {
      pollfd entry{};
      entry.fd = fd;
      entry.events = POLLIN;
      const int result = ::poll(&entry, 1, wait_ms);
      if (result > 0) return entry.revents;
      if (result == 0) return 0;
      if (errno != EINTR) return -1;
      if (timeout_ms >= 0) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        wait_ms = left.count() > 0 ? static_cast<int>(left.count()) : 0;
      }
    }
  }
};

}  // namespace

std::unique_ptr<V4l2Device> MakeSystemV4l2Device() {
  return std::make_unique<SystemV4l2Device>();
}

}  // namespace silnet::node
