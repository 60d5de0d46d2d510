#include "services/dds/field_filter.hpp"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>

#include <functional>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "commands.h"
#include "simulation.h"

namespace dds {
namespace {

namespace fdds = eprosima::fastdds::dds;
using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;

// The field of a sample, read from its serialized form (never written to: Fast DDS may
// evaluate one payload for several readers at once).
using FieldReader = std::function<std::string(const fdds::IContentFilter::SerializedPayload&)>;

template <class T, class Field>
FieldReader field_of(Field field) {
  return [field](const fdds::IContentFilter::SerializedPayload& payload) {
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload.data), payload.length);
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
    cdr.read_encapsulation();
    T sample;
    sample.deserialize(cdr);
    return field(sample);
  };
}

const std::map<std::pair<std::string, std::string>, FieldReader>& fields() {
  static const std::map<std::pair<std::string, std::string>, FieldReader> known{
      {{"cell::SimReply", "requester"}, field_of<cell::SimReply>([](const cell::SimReply& r) { return r.requester().to_string(); })},
      {{"cell::CommandEvent", "order_id"},
       field_of<cell::CommandEvent>([](const cell::CommandEvent& e) { return e.order_id().to_string(); })},
  };
  return known;
}

class FieldIn final : public fdds::IContentFilter {
 public:
  FieldIn(std::string field, FieldReader read, std::set<std::string> values)
      : field_(std::move(field)), read_(std::move(read)), values_(std::move(values)) {}
  const std::string& field() const { return field_; }
  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo&, const GUID_t&) const override {
    try {
      return values_.count(read_(payload)) > 0;
    } catch (...) {  // a sample that does not decode passes to no one
      return false;
    }
  }

 private:
  std::string field_;
  FieldReader read_;
  std::set<std::string> values_;
};

class FieldInFactory : public fdds::IContentFilterFactory {
 public:
  ReturnCode_t create_content_filter(const char*, const char* type_name, const fdds::TopicDataType*,
                                     const char* expression, const ParameterSeq& parameters,
                                     fdds::IContentFilter*& filter) override {
    // Called again with a null expression when only the parameters change.
    if (expression == nullptr && filter == nullptr) return ReturnCode_t::RETCODE_BAD_PARAMETER;
    const std::string field = expression ? expression : static_cast<FieldIn*>(filter)->field();
    const auto known = fields().find({type_name, field});
    if (known == fields().end()) return ReturnCode_t::RETCODE_BAD_PARAMETER;
    std::set<std::string> values;
    for (fdds::LoanableCollection::size_type i = 0; i < parameters.length(); ++i) values.insert(parameters[i]);
    delete static_cast<FieldIn*>(filter);
    filter = new FieldIn(field, known->second, std::move(values));
    return ReturnCode_t::RETCODE_OK;
  }
  ReturnCode_t delete_content_filter(const char*, fdds::IContentFilter* filter) override {
    delete static_cast<FieldIn*>(filter);
    return ReturnCode_t::RETCODE_OK;
  }
};

}  // namespace

void register_field_filter(fdds::DomainParticipant& participant) {
  static FieldInFactory factory;  // outlives every participant
  participant.register_content_filter_factory(kFieldFilter, &factory);
}

}  // namespace dds
