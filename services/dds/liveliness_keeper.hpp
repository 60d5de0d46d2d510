#pragma once
// Keeps the state writers of this process alive on DDS: asserts each one's liveliness at a
// third of its lease, from one thread of the process.
//
// Why not Fast DDS's AUTOMATIC liveliness: in 2.9.1 a reader's participant, on the liveliness
// message of any remote participant, asserts every AUTOMATIC writer it tracks, of every
// participant (WLPListener::onNewCacheChangeAdded calls assert_liveliness(AUTOMATIC) without
// the sender's prefix; fixed upstream later). While any other process of the cell lives, a
// dead one's writers stay alive, and it was noticed only when its participant's 20 s
// discovery lease ran out. MANUAL_BY_TOPIC liveliness is asserted per writer (a heartbeat
// with the liveliness flag), so a dead process is noticed within its lease.

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace eprosima::fastdds::dds {
class DataWriter;
}

namespace dds {

class LivelinessKeeper {
 public:
  static LivelinessKeeper& of_this_process();

  // From now on, until forget(writer) returns, `writer`'s liveliness is asserted every
  // `period`. Neither keep nor forget may be called from a DDS callback: the keeper's thread
  // may be the one delivering it (a reader in this process of a kept writer) and holds its lock.
  void keep(eprosima::fastdds::dds::DataWriter* writer, std::chrono::milliseconds period);
  // Once this returns, the keeper no longer touches `writer` (it may be deleted).
  void forget(eprosima::fastdds::dds::DataWriter* writer);

  ~LivelinessKeeper();

 private:
  LivelinessKeeper() = default;
  void run();

  struct Kept {
    eprosima::fastdds::dds::DataWriter* writer;
    std::chrono::milliseconds period;
    std::chrono::steady_clock::time_point next;
  };
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Kept> kept_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace dds
