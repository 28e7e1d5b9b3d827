#include "mapless/io/mapped_file.h"

#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <mutex>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::io {
namespace {

// The mapped ranges the handler knows: a fixed table of lock-free slots (a signal handler may not
// take a lock). begin == 0: free.
constexpr int kSlots = 64;
struct Slot {
  std::atomic<std::uintptr_t> begin{0};
  std::atomic<std::uintptr_t> end{0};
  std::atomic<bool> faulted{false};
};
Slot g_slots[kSlots];
struct sigaction g_previous {};

extern "C" void OnSigbus(int signal, siginfo_t* info, void* context) {
  const auto at = reinterpret_cast<std::uintptr_t>(info->si_addr);
  for (Slot& slot : g_slots) {
    const std::uintptr_t begin = slot.begin.load(), end = slot.end.load();
    if (begin == 0 || at < begin || at >= end) continue;
    // Zero pages over the rest of the range: the read that faulted goes on, and reads zeros.
    const std::uintptr_t page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    const std::uintptr_t from = at & ~(page - 1);
    void* zero = ::mmap(reinterpret_cast<void*>(from), end - from, PROT_READ,
                        MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0);
    if (zero == MAP_FAILED) break;
    slot.faulted.store(true);
    return;
  }
  // Not ours: whatever was there before (the default: the process ends).
  if (g_previous.sa_flags & SA_SIGINFO) {
    if (g_previous.sa_sigaction != nullptr) return g_previous.sa_sigaction(signal, info, context);
  } else if (g_previous.sa_handler != SIG_DFL && g_previous.sa_handler != SIG_IGN &&
             g_previous.sa_handler != nullptr) {
    return g_previous.sa_handler(signal);
  }
  ::signal(SIGBUS, SIG_DFL);  // returning re-runs the access, which now ends the process
}

void InstallHandler() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction action {};
    action.sa_sigaction = OnSigbus;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_SIGINFO;
    ::sigaction(SIGBUS, &action, &g_previous);
  });
}

int Register(std::uintptr_t begin, std::uintptr_t end) {
  for (int i = 0; i < kSlots; ++i) {
    std::uintptr_t expected = 0;
    if (g_slots[i].begin.compare_exchange_strong(expected, begin)) {
      g_slots[i].faulted.store(false);
      g_slots[i].end.store(end);
      return i;
    }
  }
  return -1;
}

}  // namespace

MappedFile::MappedFile(const std::string& path) {
  std::uint64_t size = 0;
  const int fd = OpenRegularFile(path, &size);
  size_ = static_cast<std::size_t>(size);
  if (size_ == 0) {
    ::close(fd);
    return;
  }
  InstallHandler();
  map_ = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
  const int error = errno;
  ::close(fd);
  if (map_ == MAP_FAILED) {
    map_ = nullptr;
    throw InputError(path + ": cannot map file: " + std::strerror(error));
  }
  const auto begin = reinterpret_cast<std::uintptr_t>(map_);
  slot_ = Register(begin, begin + size_);
  if (slot_ < 0) {  // 64 files mapped at once: unguarded reads would risk a silent death
    ::munmap(map_, size_);
    map_ = nullptr;
    throw InputError(path + ": too many files mapped at once (64)");
  }
  bytes_ = std::string_view(static_cast<const char*>(map_), size_);
}

MappedFile::~MappedFile() {
  if (slot_ >= 0) {
    g_slots[slot_].end.store(0);
    g_slots[slot_].begin.store(0);
  }
  if (map_ != nullptr) ::munmap(map_, size_);
}

bool MappedFile::changed() const { return slot_ >= 0 && g_slots[slot_].faulted.load(); }

}  // namespace mapless::io
