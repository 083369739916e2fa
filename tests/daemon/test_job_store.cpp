// The job store: SQLite round trips, the restart recovery, bad files, threads and a writer
// killed mid-update.
#include <signal.h>
#include <sqlite3.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "lamina/daemon/job_store.hpp"

namespace lamina::daemon {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// A fresh directory per test, removed afterwards (with the -wal and -shm files).
struct TempDir {
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "lamina-store-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  fs::path db() const { return path / "jobs.db"; }
  fs::path path;
};

std::unique_ptr<JobStore> open_or_fail(const fs::path& path) {
  auto store = JobStore::open(path);
  if (!store) ADD_FAILURE() << store.error().message;
  return store ? std::move(*store) : nullptr;
}

SheetRecord make_sheet(int index) {
  SheetRecord s;
  s.index = index;
  s.program_path = fmt::format("/var/lib/lamina/jobs/j/sheet-{}.nc", index);
  s.svg_path = fmt::format("/var/lib/lamina/jobs/j/sheet-{}.svg", index);
  s.material = index == 1 ? "birch plywood" : "MDF \"E1\"";
  s.thickness_mm = 6.35 + index;
  s.lines_total = 10000u + static_cast<std::size_t>(index);
  s.state = index == 1 ? SheetState::done : SheetState::cutting;
  s.last_acked_line = 4321u * static_cast<std::size_t>(index);
  s.first_unfinished_line = 4300u * static_cast<std::size_t>(index);
  s.contour = 17 * index;
  // Sheet 1 has none; sheet 2 a count above INT64_MAX (stored as its bit pattern).
  if (index != 1) s.executed_base = (std::uint64_t{1} << 63) + 5;
  s.attempt_first_line = 1200u + static_cast<std::size_t>(index);
  s.attempt_preamble_lines = 9u + static_cast<std::size_t>(index);
  s.cut_seconds = 1234.5 / index;
  return s;
}

JobRecord make_job(const std::string& id, std::int64_t created, JobState state = JobState::queued) {
  JobRecord j;
  j.id = id;
  j.state = state;
  j.model_path = "/srv/models/chair ü.stl";
  j.name = "chair ü.stl";
  j.plan_settings = {{"layer_mm", 6.35}, {"nest", {{"gap_mm", 4}, {"rotations", {0, 90, 180}}}}, {"label", "ok"}};
  j.artefact_dir = "/var/lib/lamina/jobs/" + id;
  j.error = "a 'quoted' error; DROP TABLE jobs; --";
  j.current_sheet = 2;
  j.sheets = {make_sheet(1), make_sheet(2)};
  j.summary = {{"layers", 42}, {"deviation_mm", 0.125}, {"warnings", nlohmann::json::array()}};
  j.created_unix_ms = created;
  j.updated_unix_ms = created + 5;
  return j;
}

void expect_same(const SheetRecord& a, const SheetRecord& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.program_path, b.program_path);
  EXPECT_EQ(a.svg_path, b.svg_path);
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.thickness_mm, b.thickness_mm);
  EXPECT_EQ(a.lines_total, b.lines_total);
  EXPECT_EQ(a.state, b.state);
  EXPECT_EQ(a.last_acked_line, b.last_acked_line);
  EXPECT_EQ(a.first_unfinished_line, b.first_unfinished_line);
  EXPECT_EQ(a.contour, b.contour);
  EXPECT_EQ(a.executed_base, b.executed_base);
  EXPECT_EQ(a.attempt_first_line, b.attempt_first_line);
  EXPECT_EQ(a.attempt_preamble_lines, b.attempt_preamble_lines);
  EXPECT_EQ(a.cut_seconds, b.cut_seconds);
}

void expect_same(const JobRecord& a, const JobRecord& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.state, b.state);
  EXPECT_EQ(a.model_path, b.model_path);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.plan_settings, b.plan_settings);
  EXPECT_EQ(a.artefact_dir, b.artefact_dir);
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.current_sheet, b.current_sheet);
  EXPECT_EQ(a.summary, b.summary);
  EXPECT_EQ(a.created_unix_ms, b.created_unix_ms);
  EXPECT_EQ(a.updated_unix_ms, b.updated_unix_ms);
  ASSERT_EQ(a.sheets.size(), b.sheets.size());
  for (std::size_t i = 0; i < a.sheets.size(); ++i) expect_same(a.sheets[i], b.sheets[i]);
}

JobRecord get_or_fail(const JobStore& store, const std::string& id) {
  auto job = store.get_job(id);
  if (!job) ADD_FAILURE() << job.error().message;
  if (job && !*job) ADD_FAILURE() << "no job " << id;
  return job && *job ? **job : JobRecord{};
}

// Raw access, as a second program (or an older/newer laminad) would touch the file.
std::string raw_query(const fs::path& path, const char* sql) {
  sqlite3* db = nullptr;
  std::string result = "<error>";
  if (sqlite3_open(path.c_str(), &db) == SQLITE_OK) {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr) == SQLITE_OK) {
      const int rc = sqlite3_step(stmt);
      if (rc == SQLITE_ROW) result = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
      else if (rc == SQLITE_DONE) result = "";
    }
    sqlite3_finalize(stmt);
  }
  sqlite3_close(db);
  return result;
}

TEST(JobStore, RoundTripsAFullJobWithTwoSheets) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  const JobRecord job = make_job("j-1700000000000-a1b2", 1700000000000, JobState::cutting);
  ASSERT_TRUE(store->insert_job(job));
  expect_same(get_or_fail(*store, job.id), job);

  auto missing = store->get_job("j-none");
  ASSERT_TRUE(missing) << missing.error().message;
  EXPECT_FALSE(missing->has_value());
}

TEST(JobStore, AFailedInsertLeavesNothingBehind) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  JobRecord job = make_job("j-dup", 1);
  job.sheets[1].index = 1;  // the second sheet violates the primary key after the job row went in
  auto inserted = store->insert_job(job);
  ASSERT_FALSE(inserted);
  EXPECT_NE(inserted.error().message.find(dir.db().string()), std::string::npos) << inserted.error().message;
  EXPECT_NE(inserted.error().message.find("j-dup"), std::string::npos) << inserted.error().message;
  auto found = store->get_job("j-dup");
  ASSERT_TRUE(found) << found.error().message;
  EXPECT_FALSE(found->has_value()) << "the job row was not rolled back";

  ASSERT_TRUE(store->insert_job(make_job("j-twice", 2)));
  EXPECT_FALSE(store->insert_job(make_job("j-twice", 3)));
}

TEST(JobStore, UpdateJobReplacesFieldsAndSheets) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  JobRecord job = make_job("j-upd", 100, JobState::planning);
  ASSERT_TRUE(store->insert_job(job));

  job.state = JobState::planned;
  job.name = "table.stl";
  job.error.clear();
  job.current_sheet = 0;
  job.plan_settings["layer_mm"] = 3.0;
  job.summary = {{"sheets", 1}};
  job.updated_unix_ms = 999;
  SheetRecord only = make_sheet(3);
  only.state = SheetState::pending;
  only.executed_base.reset();
  job.sheets = {only};
  ASSERT_TRUE(store->update_job(job));
  expect_same(get_or_fail(*store, job.id), job);

  auto unknown = store->update_job(make_job("j-unknown", 1));
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("j-unknown"), std::string::npos) << unknown.error().message;
}

TEST(JobStore, UpdateSheetChangesOnlyThatSheetsProgress) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  const JobRecord job = make_job("j-sheet", 100, JobState::cutting);
  ASSERT_TRUE(store->insert_job(job));

  SheetRecord progress = job.sheets[1];
  progress.state = SheetState::paused;
  progress.last_acked_line = 9001;
  progress.first_unfinished_line = 8990;
  progress.contour = 3;
  progress.executed_base = 77;
  progress.attempt_first_line = 8000;
  progress.attempt_preamble_lines = 12;
  progress.cut_seconds = 99.25;
  progress.program_path = "/elsewhere.nc";  // planned fields are not progress: left as they were
  progress.lines_total = 1;
  ASSERT_TRUE(store->update_sheet(job.id, progress));

  JobRecord expected = job;
  SheetRecord& sheet = expected.sheets[1];
  sheet.state = progress.state;
  sheet.last_acked_line = progress.last_acked_line;
  sheet.first_unfinished_line = progress.first_unfinished_line;
  sheet.contour = progress.contour;
  sheet.executed_base = progress.executed_base;
  sheet.attempt_first_line = progress.attempt_first_line;
  sheet.attempt_preamble_lines = progress.attempt_preamble_lines;
  sheet.cut_seconds = progress.cut_seconds;
  expect_same(get_or_fail(*store, job.id), expected);  // sheet 1 and the job row unchanged

  progress.executed_base.reset();  // back to "not known"
  ASSERT_TRUE(store->update_sheet(job.id, progress));
  EXPECT_FALSE(get_or_fail(*store, job.id).sheets[1].executed_base.has_value());

  progress.index = 7;
  auto missing = store->update_sheet(job.id, progress);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("sheet 7"), std::string::npos) << missing.error().message;
}

TEST(JobStore, ListsJobsOldestFirst) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  // Inserted out of order; equal creation times fall back to the id.
  for (auto [id, created] : {std::pair{"j-c", 300}, {"j-b2", 100}, {"j-d", 200}, {"j-b1", 100}})
    ASSERT_TRUE(store->insert_job(make_job(id, created)));
  auto jobs = store->list_jobs();
  ASSERT_TRUE(jobs) << jobs.error().message;
  std::vector<std::string> ids;
  for (const JobRecord& j : *jobs) ids.push_back(j.id);
  EXPECT_EQ(ids, (std::vector<std::string>{"j-b1", "j-b2", "j-d", "j-c"}));
  ASSERT_EQ(jobs->size(), 4u);
  EXPECT_EQ(jobs->front().sheets.size(), 2u);  // listed jobs come with their sheets
}

TEST(JobStore, EventsComeBackInOrderPerJob) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->insert_job(make_job("j-a", 1)));
  ASSERT_TRUE(store->insert_job(make_job("j-b", 2)));
  // Same timestamp on purpose: the order is the order of insertion, not of time.
  ASSERT_TRUE(store->add_event({"j-a", 50, "state", {{"from", "queued"}, {"to", "planning"}}}));
  ASSERT_TRUE(store->add_event({"j-b", 10, "note", {{"text", "other job"}}}));
  ASSERT_TRUE(store->add_event({"j-a", 50, "fault", {{"code", 12}, {"axes", {"A", "C"}}}}));
  ASSERT_TRUE(store->add_event({"j-a", 40, "note", nlohmann::json::object()}));

  auto events = store->events("j-a");
  ASSERT_TRUE(events) << events.error().message;
  ASSERT_EQ(events->size(), 3u);
  EXPECT_EQ((*events)[0].kind, "state");
  EXPECT_EQ((*events)[0].data, (nlohmann::json{{"from", "queued"}, {"to", "planning"}}));
  EXPECT_EQ((*events)[1].kind, "fault");
  EXPECT_EQ((*events)[1].data["axes"][1], "C");
  EXPECT_EQ((*events)[2].kind, "note");
  EXPECT_EQ((*events)[2].t_unix_ms, 40);
  for (const JobEvent& e : *events) EXPECT_EQ(e.job_id, "j-a");

  auto none = store->events("j-none");
  ASSERT_TRUE(none) << none.error().message;
  EXPECT_TRUE(none->empty());
  EXPECT_FALSE(store->add_event({"j-none", 1, "note", {}})) << "an event needs its job";
}

TEST(JobStore, RecoverAfterRestartSettlesUnfinishedJobs) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->insert_job(make_job("j-1-planning", 1, JobState::planning)));
  JobRecord cutting = make_job("j-2-cutting", 2, JobState::cutting);
  cutting.sheets[1].last_acked_line = 1234;  // current sheet 2 is `cutting`, sheet 1 `done`
  ASSERT_TRUE(store->insert_job(cutting));
  JobRecord paused = make_job("j-3-paused", 3, JobState::paused);
  paused.error = "E-stop pressed";
  paused.sheets[1].state = SheetState::paused;
  ASSERT_TRUE(store->insert_job(paused));
  ASSERT_TRUE(store->insert_job(make_job("j-4-completed", 4, JobState::completed)));
  ASSERT_TRUE(store->insert_job(make_job("j-5-queued", 5, JobState::queued)));
  const JobRecord completed = get_or_fail(*store, "j-4-completed");

  auto changed = store->recover_after_restart();
  ASSERT_TRUE(changed) << changed.error().message;
  EXPECT_EQ(*changed, (std::vector<std::string>{"j-1-planning", "j-2-cutting", "j-3-paused"}));

  EXPECT_EQ(get_or_fail(*store, "j-1-planning").state, JobState::queued);
  const JobRecord after = get_or_fail(*store, "j-2-cutting");
  EXPECT_EQ(after.state, JobState::interrupted);
  EXPECT_EQ(after.error, "the daemon stopped while this job was cutting (last acknowledged line 1234 of sheet 2)");
  ASSERT_EQ(after.sheets.size(), 2u);
  EXPECT_EQ(after.sheets[0].state, SheetState::done);
  EXPECT_EQ(after.sheets[1].state, SheetState::interrupted);
  EXPECT_EQ(after.sheets[1].last_acked_line, 1234u);  // progress kept for the resume
  EXPECT_GT(after.updated_unix_ms, cutting.updated_unix_ms);
  const JobRecord paused_after = get_or_fail(*store, "j-3-paused");
  EXPECT_EQ(paused_after.state, JobState::interrupted);
  EXPECT_EQ(paused_after.sheets[1].state, SheetState::interrupted);
  EXPECT_NE(paused_after.error.find("E-stop pressed"), std::string::npos) << paused_after.error;
  expect_same(get_or_fail(*store, "j-4-completed"), completed);
  EXPECT_EQ(get_or_fail(*store, "j-5-queued").state, JobState::queued);

  auto events = store->events("j-2-cutting");
  ASSERT_TRUE(events) << events.error().message;
  ASSERT_EQ(events->size(), 1u);
  EXPECT_EQ(events->front().kind, "state");
  EXPECT_EQ(events->front().data, (nlohmann::json{{"from", "cutting"}, {"to", "interrupted"}, {"reason", "restart"}}));
  auto planning_events = store->events("j-1-planning");
  ASSERT_TRUE(planning_events);
  ASSERT_EQ(planning_events->size(), 1u);
  EXPECT_EQ(planning_events->front().data["to"], "queued");
  auto completed_events = store->events("j-4-completed");
  ASSERT_TRUE(completed_events);
  EXPECT_TRUE(completed_events->empty());

  auto again = store->recover_after_restart();
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_TRUE(again->empty()) << "a second recovery must change nothing";
}

TEST(JobStore, RecoverInterruptsAJobBetweenSheets) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  JobRecord job = make_job("j-between", 1, JobState::sheet_done);
  job.current_sheet = 1;
  job.sheets[1].state = SheetState::pending;
  ASSERT_TRUE(store->insert_job(job));
  auto changed = store->recover_after_restart();
  ASSERT_TRUE(changed) << changed.error().message;
  EXPECT_EQ(*changed, std::vector<std::string>{"j-between"});
  const JobRecord after = get_or_fail(*store, job.id);
  EXPECT_EQ(after.state, JobState::interrupted);
  EXPECT_NE(after.error.find("after sheet 1"), std::string::npos) << after.error;
  EXPECT_EQ(after.sheets[0].state, SheetState::done);
  EXPECT_EQ(after.sheets[1].state, SheetState::pending);
}

TEST(JobStore, AnUnknownStateInTheFileIsAnError) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->insert_job(make_job("j-odd", 1)));
  EXPECT_EQ(raw_query(dir.db(), "UPDATE jobs SET state = 'exploded'"), "");
  auto got = store->get_job("j-odd");
  auto listed = store->list_jobs();
  auto recovered = store->recover_after_restart();
  ASSERT_FALSE(got);
  ASSERT_FALSE(listed);
  ASSERT_FALSE(recovered);
  for (const StoreError& error : {got.error(), listed.error(), recovered.error()}) {
    EXPECT_NE(error.message.find("exploded"), std::string::npos) << error.message;
    EXPECT_NE(error.message.find(dir.db().string()), std::string::npos) << error.message;
  }
}

TEST(JobStore, DataSurvivesClosingAndReopening) {
  TempDir dir;
  JobRecord job = make_job("j-keep", 1, JobState::cutting);
  {
    auto store = open_or_fail(dir.db());
    ASSERT_TRUE(store);
    ASSERT_TRUE(store->insert_job(job));
    job.sheets[1].last_acked_line = 5555;
    ASSERT_TRUE(store->update_sheet(job.id, job.sheets[1]));
    ASSERT_TRUE(store->add_event({job.id, 7, "note", {{"text", "kept"}}}));
  }
  EXPECT_EQ(raw_query(dir.db(), "PRAGMA journal_mode"), "wal");
  EXPECT_EQ(raw_query(dir.db(), "PRAGMA user_version"), "1");
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  expect_same(get_or_fail(*store, job.id), job);
  auto events = store->events(job.id);
  ASSERT_TRUE(events) << events.error().message;
  ASSERT_EQ(events->size(), 1u);
  EXPECT_EQ(events->front().data["text"], "kept");
}

TEST(JobStore, AFileThatIsNotADatabaseIsAStoreError) {
  TempDir dir;
  std::ofstream(dir.db()) << "this is a text file, not SQLite, and it is long enough to have a header\n";
  auto store = JobStore::open(dir.db());
  ASSERT_FALSE(store);
  EXPECT_NE(store.error().message.find(dir.db().string()), std::string::npos) << store.error().message;
  EXPECT_NE(store.error().message.find("not a database"), std::string::npos) << store.error().message;
}

TEST(JobStore, ANewerSchemaIsAStoreError) {
  TempDir dir;
  EXPECT_EQ(raw_query(dir.db(), "PRAGMA user_version = 99"), "");
  auto store = JobStore::open(dir.db());
  ASSERT_FALSE(store);
  EXPECT_NE(store.error().message.find(dir.db().string()), std::string::npos) << store.error().message;
  EXPECT_NE(store.error().message.find("99"), std::string::npos) << store.error().message;
  EXPECT_EQ(raw_query(dir.db(), "PRAGMA user_version"), "99") << "the newer file must be left alone";
  EXPECT_EQ(raw_query(dir.db(), "PRAGMA journal_mode"), "delete") << "the newer file must be left alone";
}

TEST(JobStore, SomeoneElsesDatabaseIsAStoreError) {
  TempDir dir;
  EXPECT_EQ(raw_query(dir.db(), "CREATE TABLE photos (id INTEGER)"), "");
  auto store = JobStore::open(dir.db());
  ASSERT_FALSE(store);
  EXPECT_NE(store.error().message.find(dir.db().string()), std::string::npos) << store.error().message;
}

TEST(JobStore, ThreadsShareTheStore) {
  TempDir dir;
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  JobRecord job = make_job("j-threads", 1, JobState::cutting);
  job.sheets = {make_sheet(1), make_sheet(2), make_sheet(3), make_sheet(4)};
  ASSERT_TRUE(store->insert_job(job));

  constexpr int kRounds = 200;
  std::atomic<int> failures{0};
  std::mutex first_mutex;
  std::string first_error;
  auto note = [&](const std::string& message) {
    ++failures;
    std::lock_guard lock(first_mutex);
    if (first_error.empty()) first_error = message;
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      SheetRecord sheet = job.sheets[static_cast<std::size_t>(t)];
      for (int i = 1; i <= kRounds; ++i) {
        sheet.last_acked_line = static_cast<std::size_t>(i);
        if (auto r = store->update_sheet(job.id, sheet); !r) note(r.error().message);
        if (auto r = store->add_event({job.id, i, "sheet", {{"thread", t}, {"i", i}}}); !r) note(r.error().message);
        if (auto r = store->list_jobs(); !r) note(r.error().message);
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(failures.load(), 0) << first_error;

  const JobRecord after = get_or_fail(*store, job.id);
  ASSERT_EQ(after.sheets.size(), 4u);
  for (const SheetRecord& sheet : after.sheets) EXPECT_EQ(sheet.last_acked_line, std::size_t{kRounds});
  auto events = store->events(job.id);
  ASSERT_TRUE(events) << events.error().message;
  EXPECT_EQ(events->size(), 4u * kRounds);
}

// A writer killed with SIGKILL in the middle of its update loop: the file is intact and holds
// the last committed update (or the one whose commit raced the kill), never a torn row.
TEST(JobStore, AKilledWriterLeavesTheLastCommittedProgress) {
  TempDir dir;
  const JobRecord job = make_job("j-crash", 1, JobState::cutting);
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // The child: never returns into the test runner; _exit skips atexit handlers.
    close(fds[0]);
    auto store = JobStore::open(dir.db());
    if (!store || !(*store)->insert_job(job)) _exit(2);
    SheetRecord sheet = job.sheets[1];
    const auto give_up = std::chrono::steady_clock::now() + 20s;  // if the parent never kills
    for (std::uint64_t k = 1; std::chrono::steady_clock::now() < give_up; ++k) {
      sheet.last_acked_line = k;
      sheet.first_unfinished_line = k + 7;  // fields tied to k: a torn row would show
      sheet.executed_base = 3 * k;
      sheet.cut_seconds = 0.25 * static_cast<double>(k);
      if (!(*store)->update_sheet(job.id, sheet)) _exit(3);
      if (write(fds[1], &k, sizeof k) != static_cast<ssize_t>(sizeof k)) _exit(4);  // committed
    }
    _exit(5);
  }
  close(fds[1]);
  std::uint64_t reported = 0;
  const bool started = read(fds[0], &reported, sizeof reported) == static_cast<ssize_t>(sizeof reported);
  if (started) std::this_thread::sleep_for(100ms);
  kill(child, SIGKILL);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(started) << "the child failed before its first update, exit status " << WEXITSTATUS(status);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "the child ended on its own";
  for (std::uint64_t k = 0; read(fds[0], &k, sizeof k) == static_cast<ssize_t>(sizeof k);) reported = k;
  close(fds[0]);

  EXPECT_EQ(raw_query(dir.db(), "PRAGMA integrity_check"), "ok");
  auto store = open_or_fail(dir.db());
  ASSERT_TRUE(store);
  const JobRecord after = get_or_fail(*store, job.id);
  ASSERT_EQ(after.sheets.size(), 2u);
  const SheetRecord& sheet = after.sheets[1];
  const std::uint64_t k = sheet.last_acked_line;
  EXPECT_TRUE(k == reported || k == reported + 1) << "stored " << k << ", last reported " << reported;
  EXPECT_EQ(sheet.first_unfinished_line, k + 7);
  EXPECT_EQ(sheet.executed_base, 3 * k);
  EXPECT_EQ(sheet.cut_seconds, 0.25 * static_cast<double>(k));
  expect_same(after.sheets[0], job.sheets[0]);
  EXPECT_GT(reported, 1u) << "the child should have written more than once in 100 ms";
}

}  // namespace
}  // namespace lamina::daemon
