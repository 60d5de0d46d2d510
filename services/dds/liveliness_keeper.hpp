#pragma once
// Keeps the state writers of this process alive on DDS: calls each one's assertion (which
// writes its instances' last samples again, dds::Writer::refresh) at a third of its lease,
// from one thread of the process.
//
// Why not Fast DDS's AUTOMATIC liveliness: in 2.9.1 a reader's participant, on the liveliness
// message of any remote participant, asserts every AUTOMATIC writer it tracks, of every
// participant (WLPListener::onNewCacheChangeAdded calls assert_liveliness(AUTOMATIC) without
// the sender's prefix; fixed upstream later). While any other process of the cell lives, a
// dead one's writers stay alive, and it was noticed only when its participant's 20 s
// discovery lease ran out. MANUAL_BY_TOPIC liveliness is asserted per writer, so a dead
// process is noticed within its lease.
//
// Why write the samples again rather than only assert liveliness: a process starved of CPU
// past its lease (under load, not dead) has its writers' instances NOT_ALIVE at its readers,
// and Fast DDS brings an instance back only with a new sample. A state written once (a
// capability) was then never heard again.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace dds {

class LivelinessKeeper {
 public:
  static LivelinessKeeper& of_this_process();

  // From now on, until forget(writer) returns, `assert_alive` is called every `period`, on
  // the keeper's thread, one writer at a time.
  void keep(const void* writer, std::chrono::milliseconds period, std::function<void()> assert_alive);
  // Once this returns, the keeper no longer calls `writer`'s assertion (it may be deleted),
  // but from a callback on the keeper's thread during that very assertion.
  void forget(const void* writer);

  ~LivelinessKeeper();

 private:
  LivelinessKeeper() = default;
  void run();

  struct Kept {
    const void* writer;
    std::chrono::milliseconds period;
    std::function<void()> assert_alive;
    std::chrono::steady_clock::time_point next;
  };
  std::mutex mutex_;
  std::condition_variable changed_;
  std::condition_variable done_;  // an assertion ended
  const void* asserting_ = nullptr;
  std::vector<Kept> kept_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace dds
