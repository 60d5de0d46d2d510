#pragma once
// A resource runs its function blocks from one bounded event queue, one event at a time, so
// blocks need no locks. Other threads (DDS listeners, timers) post events into it. A full
// queue is an error, never a silent drop: post() throws EventQueueOverflow, and the count of
// refused events stays visible. Events that blocks emit are never refused.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "services/runtime/function_block.hpp"

namespace fb {

class EventQueueOverflow : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Resource {
 public:
  Resource(std::string name, std::size_t queue_capacity);
  // Closes the queue before the blocks go: a DDS listener thread that posts while the
  // resource is torn down finds it closed instead of a half-destroyed map of blocks.
  ~Resource();
  Resource(const Resource&) = delete;
  Resource& operator=(const Resource&) = delete;

  const std::string& name() const { return name_; }
  // The resource owns its blocks. Returns the block for connecting and inspection.
  template <class Block>
  Block& add(std::unique_ptr<Block> block) {
    Block& ref = *block;
    adopt(std::move(block));
    return ref;
  }
  FunctionBlock& block(const std::string& name) const;

  // from.output -> to.input; both must be declared. Throws std::logic_error otherwise.
  void connect(const std::string& from, const std::string& output, const std::string& to, const std::string& input);

  // Queues an event for a block's input. Thread-safe. Throws EventQueueOverflow when full;
  // does nothing once the resource is closing.
  void post(const std::string& block, const std::string& input, Data data = {});

  // Delivers one queued event; false when the queue was empty.
  bool run_one();
  // Delivers events until none is left; returns how many.
  std::size_t run_until_idle();
  // Waits up to `timeout` for an event and delivers it; false on time-out, after calling the
  // idle hook (on this thread: what a listener thread could not post while the queue was full).
  bool wait_and_run_one(std::chrono::milliseconds timeout);
  void on_idle(std::function<void()> idle);

  std::size_t refused() const { return refused_; }
  // Events whose block threw: the exception is caught, said on stderr and counted here.
  std::size_t failed() const { return failed_; }

 private:
  friend class FunctionBlock;
  struct Delivery {
    FunctionBlock* block;
    Event event;
  };
  void adopt(std::unique_ptr<FunctionBlock> block);
  // Caller holds mutex_. Only events from outside (post) are refused when the queue is full:
  // what a block emits is the bounded consequence of an event already taken, and refusing it
  // would throw out of the resource's own thread and end the process.
  void enqueue(FunctionBlock& target, Event event, bool from_outside);
  void emitted(FunctionBlock& from, const std::string& output, const Data& data);

  std::string name_;
  std::size_t capacity_;
  std::map<std::string, std::unique_ptr<FunctionBlock>> blocks_;
  std::multimap<std::pair<FunctionBlock*, std::string>, std::pair<FunctionBlock*, std::string>> connections_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Delivery> queue_;
  bool closed_ = false;
  std::atomic<std::size_t> refused_{0};
  std::atomic<std::size_t> failed_{0};
  std::function<void()> idle_;
};

}  // namespace fb
