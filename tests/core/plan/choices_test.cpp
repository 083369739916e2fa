// The registered choices (issue 18): every table names each of its values once, a name reads
// back to its value, and an unknown name is an error that lists the known ones — the CLI, the
// machine file and laminad's settings all read names through these tables.
#include "lamina/core/bevel_profile.hpp"
#include "lamina/core/feed.hpp"
#include "lamina/core/layering.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/post.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace lamina {
namespace {

template <class E, class T>
void expect_sound(const ChoiceTable<E, T>& table, std::size_t values) {
  SCOPED_TRACE(std::string(table.what()));
  ASSERT_EQ(table.rows().size(), values) << "every value has its row";
  std::set<std::string_view> names;
  std::set<E> seen;
  for (const auto& row : table.rows()) {
    EXPECT_TRUE(names.insert(row.name).second) << "a name twice: " << row.name;
    EXPECT_TRUE(seen.insert(row.value).second) << "a value twice: " << row.name;
    EXPECT_FALSE(row.summary.empty()) << row.name;
    auto parsed = table.parse(row.name);
    ASSERT_TRUE(parsed) << row.name;
    EXPECT_EQ(*parsed, row.value);
    EXPECT_STREQ(table.name_of(row.value), std::string(row.name).c_str());
  }
  auto bad = table.parse("nonsense");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::invalid_argument);
  EXPECT_EQ(bad.error().message,
            "unknown " + std::string(table.what()) + " 'nonsense' (known: " + table.names_text() + ")");
}

TEST(Choices, EveryTableNamesEachValueOnce) {
  expect_sound(cut_sides(), 3);
  expect_sound(bevel_strategies(), 3);
  expect_sound(layering_methods(), 2);
  expect_sound(nest_methods(), 2);
  expect_sound(feed_models(), 2);
  expect_sound(post_dialects(), 3);
}

TEST(Choices, NamesAreTheOnesUsersType) {
  EXPECT_EQ(post_dialects().names_text(), "grblhal, fanuc, linuxcnc");
  EXPECT_EQ(bevel_strategies().names_text(), "curved, sloped, vertical");
  EXPECT_EQ(feed_models().names_text(), "zeng-kim, limbachiya-patel");
  EXPECT_STREQ(feed_model_name(FeedModel::zeng_kim), "zeng_kim") << "report.json's spelling, kept";
  ASSERT_TRUE(parse_feed_model("zeng-kim"));
  EXPECT_EQ(*parse_feed_model("zeng-kim"), FeedModel::zeng_kim);
}

TEST(Choices, ADialectsRtcpIsATraitThePostChecks) {
  for (const auto& d : post_dialects().rows()) {
    HeadKinematics head;
    head.rtcp = true;
    SheetToolpath empty;
    PostParams params;
    params.dialect = d.value;
    auto program = post_program(empty, head, params);
    if (d.traits.rtcp) {
      EXPECT_TRUE(program) << d.name << ": " << (program ? "" : program.error().message);
    } else {
      ASSERT_FALSE(program) << d.name;
      EXPECT_EQ(program.error().code, ErrorCode::unsupported);
      EXPECT_NE(program.error().message.find(std::string(d.name) + " has no RTCP"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace lamina
