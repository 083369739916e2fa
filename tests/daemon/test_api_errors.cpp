// Issue 18: the job domain answers in its own error kinds; api_methods maps them to the
// JSON-RPC codes of docs/api.md in one place. Every kind has its own code.
#include <gtest/gtest.h>

#include <set>

#include "api_methods.hpp"

namespace lamina::daemon {
namespace {

TEST(ApiErrors, EveryJobErrorKindHasItsDocumentedCode) {
  const std::pair<JobErrorKind, int> documented[] = {
      {JobErrorKind::bad_request, -32602},  {JobErrorKind::not_found, -32010},
      {JobErrorKind::wrong_state, -32011},  {JobErrorKind::machine_busy, -32012},
      {JobErrorKind::storage, -32014},      {JobErrorKind::shutting_down, -32015},
      {JobErrorKind::internal, -32603}};
  std::set<int> codes;
  for (const auto& [kind, code] : documented) {
    const RpcError e = rpc_error(JobError{kind, "why"});
    EXPECT_EQ(e.code, code) << static_cast<int>(kind);
    EXPECT_EQ(e.message, "why");
    EXPECT_TRUE(e.data.is_null());
    codes.insert(e.code);
  }
  EXPECT_EQ(codes.size(), std::size(documented)) << "two kinds share a code";
}

}  // namespace
}  // namespace lamina::daemon
