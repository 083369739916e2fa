// Who may use the web console (issue 19), sans-IO: the sessions, the login limiter, the Host and
// Origin checks, the cookie, the password hashes. Time is an argument, so expiry is tested
// without waiting.
#include <gtest/gtest.h>

#include "http/login_limiter.hpp"
#include "http/passwords.hpp"
#include "http/session_table.hpp"
#include "http/web_access.hpp"

namespace lamina::daemon::http {
namespace {

TEST(SessionTable, ASessionLastsItsLifetimeAndNoLonger) {
  SessionTable table(3600, 8);
  const std::string token = table.open("ana", Role::machine_operator, 1000);
  EXPECT_EQ(token.size(), 64U);
  auto found = table.find(token, 1000 + 3599);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->user, "ana");
  EXPECT_EQ(found->role, Role::machine_operator);
  EXPECT_FALSE(table.find(token, 1000 + 3600));
  EXPECT_FALSE(table.find(token, 1000)) << "an expired session is gone, not just hidden";
}

TEST(SessionTable, TokensAreUnguessableAndLogoutEndsOne) {
  SessionTable table(3600, 8);
  const std::string a = table.open("ana", Role::viewer, 0);
  const std::string b = table.open("ana", Role::viewer, 0);
  EXPECT_NE(a, b);
  EXPECT_FALSE(table.find("", 1));
  EXPECT_FALSE(table.find(a.substr(0, 63) + (a.back() == '0' ? "1" : "0"), 1));
  table.close(a);
  EXPECT_FALSE(table.find(a, 1));
  EXPECT_TRUE(table.find(b, 1));
}

TEST(SessionTable, AFullTableDropsTheSessionNearestItsEnd) {
  SessionTable table(100, 2);
  const std::string first = table.open("a", Role::viewer, 0);
  const std::string second = table.open("b", Role::viewer, 10);
  const std::string third = table.open("c", Role::viewer, 20);
  EXPECT_EQ(table.size(), 2U);
  EXPECT_FALSE(table.find(first, 21));
  EXPECT_TRUE(table.find(second, 21));
  EXPECT_TRUE(table.find(third, 21));
}

TEST(LoginLimiter, FiveFailuresFromOneAddressLockItOutForTheLockout) {
  LoginLimiter limiter(LoginLimits{5, 60, 60, 100});
  for (int i = 0; i < 4; ++i) {
    limiter.failed("10.0.0.5", "user" + std::to_string(i), 100 + i);
    EXPECT_FALSE(limiter.refused_for("10.0.0.5", "other", 100 + i)) << i;
  }
  limiter.failed("10.0.0.5", "user4", 104);
  const auto wait = limiter.refused_for("10.0.0.5", "anyone", 104);
  ASSERT_TRUE(wait);
  EXPECT_DOUBLE_EQ(*wait, 60);
  EXPECT_FALSE(limiter.refused_for("10.0.0.6", "anyone", 104)) << "another address is not locked";
  EXPECT_FALSE(limiter.refused_for("10.0.0.5", "anyone", 164));
}

TEST(LoginLimiter, OneNameGuessedFromManyAddressesIsLockedToo) {
  LoginLimiter limiter(LoginLimits{5, 60, 30, 100});
  for (int i = 0; i < 5; ++i) limiter.failed("10.0.0." + std::to_string(i), "ana", 10);
  EXPECT_TRUE(limiter.refused_for("10.9.9.9", "ana", 11));
  EXPECT_FALSE(limiter.refused_for("10.9.9.9", "bob", 11));
}

TEST(LoginLimiter, FailuresSpreadOverWindowsDoNotAddUp) {
  LoginLimiter limiter(LoginLimits{3, 60, 60, 100});
  limiter.failed("a", "u", 0);
  limiter.failed("a", "u", 1);
  limiter.failed("a", "u", 61);  // a new window
  EXPECT_FALSE(limiter.refused_for("a", "u", 62));
}

TEST(LoginLimiter, ASuccessClearsTheAddressButNotTheName) {
  LoginLimiter limiter(LoginLimits{2, 60, 60, 100});
  limiter.failed("a", "ana", 0);
  limiter.failed("b", "ana", 0);  // "ana" is locked now; "a" has one failure
  limiter.succeeded("a");
  EXPECT_TRUE(limiter.refused_for("c", "ana", 1));
  limiter.failed("a", "bob", 2);
  EXPECT_FALSE(limiter.refused_for("a", "carl", 2)) << "a's count started again";
}

TEST(LoginLimiter, TracksAtMostMaxKeys) {
  LoginLimiter limiter(LoginLimits{2, 60, 60, 4});
  for (int i = 0; i < 100; ++i) limiter.failed("addr" + std::to_string(i), "u" + std::to_string(i), i);
  // Only the newest keys are remembered: the newest address's first failure is still counted.
  limiter.failed("addr99", "x", 100);
  EXPECT_TRUE(limiter.refused_for("addr99", "y", 100));
  EXPECT_FALSE(limiter.refused_for("addr0", "y", 100));
}

AccessSettings with_users() {
  AccessSettings s;
  s.users = {WebUser{"ana", Role::machine_operator, "$argon2id$v=19$m=65536,t=2,p=1$x$y"}};
  s.session_lifetime_s = 600;
  s.server_names = {"cell-7.shop.example"};
  s.allowed_origins = {"https://console.shop.example"};
  s.machine_name = "Cell7";
  return s;
}

TEST(WebAccess, TheHostMustNameThisServer) {
  WebAccess access(with_users());
  for (const char* ok : {"127.0.0.1:8080", "localhost:8080", "LOCALHOST", "[::1]:8080", "192.168.1.20", "cell7:80",
                         "cell-7.shop.example"})
    EXPECT_TRUE(access.check_host(ok)) << ok;
  for (const char* bad : {"", "evil.example:8080", "cell7.evil.example", "localhost.evil.example"}) {
    auto r = access.check_host(bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_EQ(r.error().status, 400) << bad;
  }
}

TEST(WebAccess, AnotherSitesOriginIsRefused) {
  WebAccess access(with_users());
  EXPECT_TRUE(access.check_origin("", "localhost:8080")) << "not a browser";
  EXPECT_TRUE(access.check_origin("http://localhost:8080", "localhost:8080"));
  EXPECT_TRUE(access.check_origin("https://console.shop.example", "localhost:8080"));
  auto foreign = access.check_origin("http://evil.example", "localhost:8080");
  ASSERT_FALSE(foreign);
  EXPECT_EQ(foreign.error().status, 403);
  EXPECT_NE(foreign.error().message.find("evil.example"), std::string::npos);
  EXPECT_FALSE(access.check_origin("http://localhost:9999", "localhost:8080")) << "another port is another origin";
  EXPECT_FALSE(access.check_origin("null", "localhost:8080"));
}

TEST(WebAccess, WithUsersAVisitorNeedsALiveSession) {
  WebAccess access(with_users());
  EXPECT_EQ(access.visitor("", 0).error().status, 401);
  EXPECT_EQ(access.visitor("lamina_session=0123", 0).error().status, 401);
  const std::string token = access.sessions().open("ana", Role::machine_operator, 0);
  auto who = access.visitor("theme=dark; lamina_session=" + token + "; x=1", 10);
  ASSERT_TRUE(who) << who.error().message;
  EXPECT_EQ(who->user, "ana");
  EXPECT_EQ(who->role, Role::machine_operator);
  EXPECT_TRUE(who->logged_in);
  EXPECT_EQ(access.visitor("lamina_session=" + token, 601).error().status, 401);
}

TEST(WebAccess, WithoutUsersEveryVisitorOnlyWatches) {
  WebAccess access(AccessSettings{});
  auto who = access.visitor("", 0);
  ASSERT_TRUE(who);
  EXPECT_EQ(who->role, Role::viewer);
  EXPECT_FALSE(who->logged_in);
}

TEST(WebAccess, TheSessionCookieIsHttpOnlyAndStrict) {
  WebAccess access(with_users());
  const std::string cookie = access.session_cookie("abc");
  EXPECT_EQ(cookie, "lamina_session=abc; Path=/; Max-Age=600; HttpOnly; SameSite=Strict");
  AccessSettings tls = with_users();
  tls.tls = true;
  EXPECT_NE(WebAccess(tls).session_cookie("abc").find("; Secure"), std::string::npos);
  EXPECT_NE(access.cleared_cookie().find("Max-Age=0"), std::string::npos);
}

TEST(CookieValue, FindsTheNamedCookieOnly) {
  EXPECT_EQ(cookie_value("a=1; lamina_session=xyz; b=2", "lamina_session"), "xyz");
  EXPECT_EQ(cookie_value("lamina_session=xyz", "lamina_session"), "xyz");
  EXPECT_EQ(cookie_value("not_lamina_session=xyz", "lamina_session"), "");
  EXPECT_EQ(cookie_value("", "lamina_session"), "");
}

TEST(Passwords, AHashVerifiesItsPasswordOnly) {
  auto hash = hash_password("correct horse");
  ASSERT_TRUE(hash) << hash.error();
  EXPECT_TRUE(hash->starts_with("$argon2id$v=19$m=65536,t=2,p=1$")) << *hash;
  EXPECT_TRUE(check_password_hash(*hash));
  EXPECT_TRUE(verify_password(*hash, "correct horse"));
  EXPECT_FALSE(verify_password(*hash, "correct horse "));
  EXPECT_FALSE(verify_password(*hash, ""));
  EXPECT_NE(*hash, *hash_password("correct horse")) << "salted";
  EXPECT_FALSE(hash_password(""));
}

TEST(Passwords, OnlyArgon2idHashesAreAccepted) {
  EXPECT_FALSE(check_password_hash("hunter2"));
  EXPECT_FALSE(check_password_hash("$2b$12$abcdefghijklmnopqrstuv"));       // bcrypt
  EXPECT_FALSE(check_password_hash("$argon2i$v=19$m=65536,t=2,p=1$a$b"));  // not the id variant
  EXPECT_FALSE(verify_password("garbage", "x"));
}

}  // namespace
}  // namespace lamina::daemon::http
