#pragma once
// IEC 61499 communication service blocks bound to DDS topics. The mapping between event
// data and the topic's type is the block's only knowledge of the type, given by the
// service that uses it; the runtime stays free of DDS.
//
//   PublishBlock:   REQ (data) -> writes one sample -> CNF, or ERROR (reason)
//   SubscribeBlock: a sample arrives -> IND (data); its writers are gone -> GONE (key data).
//                   A mapping that returns no data drops the sample on the listener thread
//                   (one meant for another resource never takes a place in this queue).

#include <functional>
#include <iostream>
#include <memory>

#include "services/dds/endpoints.hpp"
#include "services/runtime/resource.hpp"

namespace dds {

template <class T, class PubSubType>
class PublishBlock : public fb::FunctionBlock {
 public:
  using ToSample = std::function<T(const fb::Data&)>;

  PublishBlock(std::string name, ParticipantPtr participant, const std::string& topic, TopicKind kind, ToSample to_sample)
      : FunctionBlock(std::move(name)),
        writer_(std::make_unique<Writer<T, PubSubType>>(std::move(participant), topic, kind)),
        to_sample_(std::move(to_sample)) {
    declare_input("REQ");
    declare_output("CNF");
    declare_output("ERROR", {"reason"});
  }

  Writer<T, PubSubType>& writer() { return *writer_; }

  void receive(const fb::Event& event) override {
    if (event.name != "REQ") return;
    if (writer_->write(to_sample_(event.data))) {
      emit("CNF");
    } else {
      emit("ERROR", {{"reason", std::string("DDS write failed on ") + name()}});
    }
  }

 private:
  std::unique_ptr<Writer<T, PubSubType>> writer_;
  ToSample to_sample_;
};

template <class T, class PubSubType>
class SubscribeBlock : public fb::FunctionBlock {
 public:
  using ToData = std::function<fb::Data(const T&)>;

  SubscribeBlock(std::string name, ParticipantPtr participant, std::string topic, TopicKind kind, ToData to_data)
      : FunctionBlock(std::move(name)), participant_(std::move(participant)), topic_(std::move(topic)), kind_(kind),
        to_data_(std::move(to_data)) {
    declare_input("RECEIVED");  // from the DDS listener thread, through the resource's queue
    declare_input("LOST");
    declare_output("IND");
    declare_output("GONE");
  }

  // Starts listening; call once the block is on its resource and wired.
  void start() {
    reader_ = std::make_unique<Reader<T, PubSubType>>(
        participant_, topic_, kind_, [this](const T& s) { deliver("RECEIVED", s); },
        [this](const T& s) { deliver("LOST", s); });
  }

  void receive(const fb::Event& event) override {
    if (event.name == "RECEIVED") emit("IND", event.data);
    if (event.name == "LOST") emit("GONE", event.data);
  }

 private:
  void deliver(const char* input, const T& sample) {
    try {
      fb::Data data = to_data_(sample);
      if (data.empty()) return;
      post_to_self(input, std::move(data));
    } catch (const std::exception& e) {
      // Nothing to return to on a listener thread: say it loudly; the resource counts it.
      std::cerr << "error: " << name() << " on " << topic_ << ": " << e.what() << '\n';
    }
  }

  ParticipantPtr participant_;
  std::string topic_;
  TopicKind kind_;
  ToData to_data_;
  std::unique_ptr<Reader<T, PubSubType>> reader_;
};

}  // namespace dds
