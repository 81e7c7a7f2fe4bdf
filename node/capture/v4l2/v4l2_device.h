#pragma once
// The system calls a V4L2 capture source makes on its device node, behind one small interface,
// so the capture state machine can be tested against a scripted fake device (CI hosts have no
// cameras) and run unchanged against the kernel.

#include <sys/mman.h>
#include <sys/types.h>

#include <cstddef>
#include <memory>
#include <string>

namespace silnet::node {

// The device system calls of V4l2Source. Errors are reported like the system calls report
// them: a failed call returns -1 (MAP_FAILED for Mmap) and sets errno.
class V4l2Device {
 public:
  virtual ~V4l2Device() = default;

  // Opens the device node `path` with open(2) `flags`; returns a file descriptor >= 0.
  virtual int Open(const std::string& path, int flags) = 0;
  // Closes `fd`; returns 0 on success. The descriptor is released even when it fails.
  virtual int Close(int fd) = 0;
  // Performs ioctl `request` on `fd`; returns 0 (or the ioctl's non-negative result) on
  // success. Calls interrupted by a signal are repeated, so errno is never EINTR.
  virtual int Ioctl(int fd, unsigned long request, void* arg) = 0;
  // Maps `length` bytes of `fd` at `offset` shared and read-write; returns the address.
  virtual void* Mmap(size_t length, int fd, off_t offset) = 0;
  // Unmaps a mapping returned by Mmap; returns 0 on success.
  virtual int Munmap(void* address, size_t length) = 0;
  // Waits up to `timeout_ms` (negative: no limit) for `fd` to have a frame to dequeue or an
  // error. Returns the poll(2) revents of `fd` (POLLIN, POLLERR, POLLHUP, POLLNVAL, ...) when
  // something happened, 0 on timeout. Interrupted waits continue with the time left.
  virtual int Poll(int fd, int timeout_ms) = 0;
};

// The real device calls (open, close, ioctl, mmap, munmap, poll of the running kernel).
std::unique_ptr<V4l2Device> MakeSystemV4l2Device();

}  // namespace silnet::node
