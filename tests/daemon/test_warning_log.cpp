// The daemon's warning log (warning_log.hpp): what the console's Warnings shows. Warnings and
// errors only, oldest first, the newest `capacity` kept, and only those after a seq on request.
#include "warning_log.hpp"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

namespace lamina::daemon {
namespace {

TEST(WarningLog, KeepsTheNewestWarningsAndErrorsInOrder) {
  auto log = std::make_shared<WarningLog>(3);
  spdlog::logger logger("cut", log);
  logger.set_level(spdlog::level::trace);
  logger.info("planned");  // not a warning: not kept
  logger.warn("held: {}", "door open");
  logger.error("link lost");
  logger.debug("detail");
  logger.warn("second warning");
  logger.critical("fourth kept, first dropped");

  const auto all = log->since(0);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].message, "link lost");
  EXPECT_EQ(all[0].level, "error");
  EXPECT_EQ(all[0].source, "cut");
  EXPECT_EQ(all[1].message, "second warning");
  EXPECT_EQ(all[1].level, "warning");
  EXPECT_EQ(all[2].level, "critical");
  EXPECT_EQ(all[0].seq, 2u);  // the dropped one had 1
  EXPECT_EQ(all[2].seq, 4u);
  EXPECT_GT(all[0].t_unix_ms, 1'700'000'000'000);

  const auto newer = log->since(all[1].seq);
  ASSERT_EQ(newer.size(), 1u);
  EXPECT_EQ(newer[0].message, "fourth kept, first dropped");
  EXPECT_TRUE(log->since(4).empty());
}

}  // namespace
}  // namespace lamina::daemon
