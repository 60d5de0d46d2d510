#include <algorithm>
#include <iostream>

#include "services/runtime/basic_block.hpp"
#include "services/runtime/resource.hpp"

namespace fb {

// --- Event data ---------------------------------------------------------------------------

std::string join_names(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

std::vector<std::string> split_names(const std::string& joined) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < joined.size()) {
    const std::size_t comma = std::min(joined.find(',', start), joined.size());
    if (comma > start) out.push_back(joined.substr(start, comma - start));
    start = comma + 1;
  }
  return out;
}

// --- FunctionBlock --------------------------------------------------------------------------

namespace {
bool declared(const std::vector<EventPort>& ports, const std::string& name) {
  return std::any_of(ports.begin(), ports.end(), [&](const EventPort& p) { return p.name == name; });
}
}  // namespace

bool FunctionBlock::has_input(const std::string& event) const { return declared(inputs_, event); }
bool FunctionBlock::has_output(const std::string& event) const { return declared(outputs_, event); }

void FunctionBlock::declare_input(std::string name, std::vector<std::string> with) {
  inputs_.push_back({std::move(name), std::move(with)});
}

void FunctionBlock::declare_output(std::string name, std::vector<std::string> with) {
  outputs_.push_back({std::move(name), std::move(with)});
}

void FunctionBlock::emit(const std::string& output, Data data) {
  if (!has_output(output)) throw std::logic_error(name_ + " has no event output " + output);
  if (!resource_) throw std::logic_error(name_ + " emitted " + output + " before joining a resource");
  resource_->emitted(*this, output, data);
}

void FunctionBlock::post_to_self(const std::string& input, Data data) {
  if (!resource_) throw std::logic_error(name_ + " posted " + input + " before joining a resource");
  resource_->post(name_, input, std::move(data));
}

// --- Resource -------------------------------------------------------------------------------

Resource::Resource(std::string name, std::size_t queue_capacity) : name_(std::move(name)), capacity_(queue_capacity) {}

Resource::~Resource() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    queue_.clear();
  }
  blocks_.clear();  // subscribe blocks stop their DDS readers here
}

void Resource::adopt(std::unique_ptr<FunctionBlock> block) {
  if (blocks_.count(block->name())) throw std::logic_error(name_ + " has a block " + block->name() + " already");
  block->resource_ = this;
  blocks_.emplace(block->name(), std::move(block));
}

FunctionBlock& Resource::block(const std::string& name) const {
  const auto it = blocks_.find(name);
  if (it == blocks_.end()) throw std::logic_error(name_ + " has no block " + name);
  return *it->second;
}

void Resource::connect(const std::string& from, const std::string& output, const std::string& to,
                       const std::string& input) {
  FunctionBlock& source = block(from);
  FunctionBlock& target = block(to);
  if (!source.has_output(output)) throw std::logic_error(from + " has no event output " + output);
  if (!target.has_input(input)) throw std::logic_error(to + " has no event input " + input);
  connections_.emplace(std::make_pair(&source, output), std::make_pair(&target, input));
}

void Resource::enqueue(FunctionBlock& target, Event event, bool from_outside) {
  if (from_outside && queue_.size() >= capacity_) {
    ++refused_;
    throw EventQueueOverflow("event queue of resource " + name_ + " is full (" + std::to_string(capacity_) +
                             " events): refused " + target.name() + "." + event.name);
  }
  queue_.push_back({&target, std::move(event)});
}

void Resource::post(const std::string& name, const std::string& input, Data data) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return;
    FunctionBlock& target = block(name);
    if (!target.has_input(input)) throw std::logic_error(name + " has no event input " + input);
    enqueue(target, {input, std::move(data)}, true);
  }
  ready_.notify_one();
}

void Resource::emitted(FunctionBlock& from, const std::string& output, const Data& data) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto [begin, end] = connections_.equal_range({&from, output});
  for (auto it = begin; it != end; ++it) enqueue(*it->second.first, {it->second.second, data}, false);
}

bool Resource::run_one() {
  Delivery next;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.empty()) return false;
    next = std::move(queue_.front());
    queue_.pop_front();
  }
  try {
    next.block->receive(next.event);
  } catch (const std::exception& e) {
    // A block's bug or a sample no check foresaw: the event fails alone, the resource and
    // its thread go on, and the failure is counted and said.
    ++failed_;
    std::cerr << "error: " << name_ << ": " << next.block->name() << "." << next.event.name << ": " << e.what() << '\n';
  }
  return true;
}

std::size_t Resource::run_until_idle() {
  std::size_t count = 0;
  while (run_one()) ++count;
  return count;
}

bool Resource::wait_and_run_one(std::chrono::milliseconds timeout) {
  bool ready = false;
  std::function<void()> idle;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    ready = ready_.wait_for(lock, timeout, [&] { return !queue_.empty(); });
    if (!ready) idle = idle_;
  }
  if (ready) return run_one();
  for (auto& [name, block] : blocks_) {
    try {
      block->idle();
    } catch (const std::exception& e) {
      ++failed_;
      std::cerr << "error: " << name_ << ": " << name << " when idle: " << e.what() << '\n';
    }
  }
  if (idle) idle();
  return false;
}

void Resource::on_idle(std::function<void()> idle) {
  std::lock_guard<std::mutex> lock(mutex_);
  idle_ = std::move(idle);
}

}  // namespace fb
