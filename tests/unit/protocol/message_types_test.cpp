// The message table (message_types.h) against the .proto files, by protobuf reflection: every
// MessageType value has one row, every Envelope.body field has one row, and each row's body
// type, field and type value agree. A message added to the .proto files but not to the table
// (or the other way round) fails here.
#include <cctype>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include <coredem/protocol/message.h>
#include <coredem/protocol/message_types.h>

using namespace coredem::protocol;
namespace v1 = coredem::v1;

namespace {

TEST(MessageTypes, EveryMessageTypeValueHasOneRow) {
  const auto* e = v1::MessageType_descriptor();
  for (int i = 0; i < e->value_count(); ++i) {
    const auto type = static_cast<v1::MessageType>(e->value(i)->number());
    if (type == v1::MESSAGE_TYPE_UNSPECIFIED) {
      EXPECT_EQ(findMessageType(type), nullptr);
      continue;
    }
    int rows = 0;
    for (const auto& row : kMessageTypes) {
      rows += row.type == type ? 1 : 0;
    }
    EXPECT_EQ(rows, 1) << e->value(i)->name() << ": add one row to COREDEM_PROTOCOL_MESSAGES";
  }
}

TEST(MessageTypes, EveryBodyFieldHasOneRowAndTheNamesAgree) {
  const auto* env = v1::Envelope::descriptor();
  const auto* body = env->FindOneofByName("body");
  ASSERT_NE(body, nullptr);
  EXPECT_EQ(static_cast<std::size_t>(body->field_count()), kMessageTypes.size());
  std::set<int> cases;
  for (const auto& row : kMessageTypes) {
    const auto* field = env->FindFieldByName(std::string(row.field));
    ASSERT_NE(field, nullptr) << row.field << " is not an Envelope field";
    EXPECT_EQ(field->containing_oneof(), body) << row.field;
    EXPECT_EQ(field->number(), static_cast<int>(row.bodyCase)) << row.field;
    EXPECT_TRUE(cases.insert(row.bodyCase).second) << row.field << " listed twice";
    // MESSAGE_TYPE_<FIELD IN UPPER CASE>
    std::string upper;
    for (const char c : row.field) {
      upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
    EXPECT_EQ(v1::MessageType_Name(row.type), "MESSAGE_TYPE_" + upper);
  }
}

TEST(MessageTypes, SetBodySetsTheTypeOfItsRow) {
  Message m;
  m.setBody(v1::StepGrant{});
  EXPECT_EQ(m.type(), v1::MESSAGE_TYPE_STEP_GRANT);
  EXPECT_EQ(m.envelope().body_case(), MessageTraits<v1::StepGrant>::bodyCase);
  m.setBody(v1::Ack{});
  EXPECT_EQ(m.type(), MessageTraits<v1::Ack>::type);
  static_assert(MessageTraits<v1::GasFields>::field == "gas_fields");
}

} // namespace
