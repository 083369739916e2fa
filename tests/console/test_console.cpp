// The web console in a real browser (issue 19): lamina-sim and laminad as the shop runs them,
// the console served from the build, and web/e2e/console.e2e.mjs driving Debian's chromium
// through playwright-core: an engineer uploads and plans the knob, a viewer's confirm is
// refused, an operator confirms every sheet, holds and resumes once, and the job completes;
// a wrong password, a missing cookie, a foreign Origin and "../" are refused. Screenshots of each
// view go to Testing/console-shots/. This side checks what the browser cannot see: the hold
// reached the controller.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "daemon_fixture.hpp"
#include "http/passwords.hpp"
#include "http_test_client.hpp"

namespace lamina::daemon::testing {
namespace {

std::string web_user(const std::string& name, const std::string& role, const std::string& password) {
  return fmt::format("[[http.users]]\nname = \"{}\"\nrole = \"{}\"\npassword_hash = \"{}\"\n", name, role,
                     *http::hash_password(password));
}

// The e2e script's output, and its exit status.
std::pair<std::string, int> run_browser(const std::vector<std::string>& env) {
  std::string command;
  for (const auto& e : env) command += e + " ";
  command += fmt::format("{} {} 2>&1", LAMINA_NODE, LAMINA_WEB_E2E);
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return {"cannot start node", -1};
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) {
    out += buf;
    std::fputs(buf, stdout);  // progress in ctest's log as it happens
  }
  const int status = ::pclose(pipe);
  return {out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

std::string lines_with(const std::string& file, const std::string& text) {
  std::ifstream in(file);
  std::string out;
  for (std::string line; std::getline(in, line);)
    if (line.find(text) != std::string::npos) out += line + "\n";
  return out;
}

TEST(ConsoleInABrowser, EngineerPlansViewerIsRefusedOperatorCutsEverySheet) {
  Cell cell;
  const int port = free_loopback_port();
  const std::string users = web_user("eng", "engineer", "eng-pass") + web_user("ana", "operator", "ana-pass") +
                            web_user("vic", "viewer", "vic-pass");
  Laminad daemon(cell.config("", fmt::format("listen = \"127.0.0.1:{}\"\nstatic_dir = \"{}\"\n{}", port, LAMINA_WEB_BUILD, users)),
                 cell.dir.file(""));
  RpcClient c = connect(cell.socket());  // waits for the daemon's socket, so the console is up too
  // The rack the engineer plans against: the machine's default sheet, with the slot the
  // operator's prompt must name.
  std::filesystem::create_directories(cell.dir.file("parts"));
  const std::string rack = cell.dir.file("parts/rack.toml");
  std::ofstream(rack) << "[[sheet]]\nthickness_mm = 5\nwidth_mm = 1250\nlength_mm = 2500\nmaterial = \"aluminium 6061-T6\"\n"
                         "slot = \"B2 top\"\n";
  const std::string shots = std::string(LAMINA_SHOTS_DIR);
  const auto [out, status] = run_browser({
      fmt::format("LAMINA_URL=http://127.0.0.1:{}", port),
      fmt::format("LAMINA_MODEL={}/knob.stl", LAMINA_EXAMPLES_DIR),
      fmt::format("LAMINA_STOCK_FILE={}", rack),
      fmt::format("LAMINA_SHOTS={}", shots),
      R"(LAMINA_USERS='{"engineer":["eng","eng-pass"],"operator":["ana","ana-pass"],"viewer":["vic","vic-pass"]}')",
  });
  EXPECT_EQ(status, 0) << out << "\n--- jobs ---\n" << call_ok(c, "job.list").dump(1) << "\n--- laminad ---\n" << daemon.log();
  EXPECT_NE(out.find("{\"ok\":true"), std::string::npos) << out;
  // The model came as the form's POST, streamed to disk (not in base64 pieces over the socket).
  EXPECT_NE(daemon.log().find("http: eng uploads knob.stl ("), std::string::npos) << daemon.log();
  // The browser's hold went down the line as grbl's real-time byte, and the cycle start after it.
  const std::string realtime = lines_with(cell.log(), "\"realtime\"");
  EXPECT_NE(realtime.find("\"command\":\"feed_hold\""), std::string::npos) << realtime;
  EXPECT_NE(realtime.find("\"command\":\"cycle_start\""), std::string::npos) << realtime << daemon.log();
}

}  // namespace
}  // namespace lamina::daemon::testing
