// The web server's routing (issue 19), string by string: what a target may name and what is
// refused before anything touches the filesystem.
#include <gtest/gtest.h>

#include "http/http_routes.hpp"

namespace lamina::daemon::http {
namespace {

const std::string kJob = "j-1764892800123-a3f9";

ArtefactRequest artefact_of(const std::string& target) {
  auto r = route_get(target);
  EXPECT_TRUE(r.has_value()) << target << ": " << (r ? "" : r.error().message);
  if (!r || !std::holds_alternative<ArtefactRequest>(*r)) {
    ADD_FAILURE() << target << " is not an artefact";
    return {};
  }
  return std::get<ArtefactRequest>(*r);
}

std::string static_of(const std::string& target) {
  auto r = route_get(target);
  EXPECT_TRUE(r.has_value()) << target << ": " << (r ? "" : r.error().message);
  if (!r || !std::holds_alternative<StaticRequest>(*r)) return "<not static>";
  return std::get<StaticRequest>(*r).relative;
}

RouteError refusal(const std::string& target) {
  auto r = route_get(target);
  EXPECT_FALSE(r.has_value()) << target << " was accepted";
  return r ? RouteError{0, ""} : r.error();
}

TEST(HttpRoutes, AJobsArtefactsAreNamesFromAFixedList) {
  EXPECT_EQ(artefact_of("/api/jobs/" + kJob + "/report.json").kind, Artefact::report);
  EXPECT_EQ(artefact_of("/api/jobs/" + kJob + "/stack.stl").kind, Artefact::stack);
  EXPECT_EQ(artefact_of("/api/jobs/" + kJob + "/model").kind, Artefact::model);
  const ArtefactRequest svg = artefact_of("/api/jobs/" + kJob + "/sheet-12.svg");
  EXPECT_EQ(svg.kind, Artefact::sheet_drawing);
  EXPECT_EQ(svg.sheet, 12);
  EXPECT_EQ(svg.job_id, kJob);
  EXPECT_EQ(artefact_file_name(svg), "sheet-12.svg");
  const ArtefactRequest nc = artefact_of("/api/jobs/" + kJob + "/sheet-1.nc?download=1");
  EXPECT_EQ(nc.kind, Artefact::sheet_program);
  EXPECT_EQ(artefact_file_name(nc), "sheet-1.nc");
}

TEST(HttpRoutes, AnythingElseUnderAJobIsNotFound) {
  for (const std::string name : {"plan.log", "sheet-0.svg", "sheet-01.svg", "sheet-x.nc", "sheet-.svg", "jobs.db",
                                 "sheet-99999999999.svg"}) {
    const RouteError e = refusal("/api/jobs/" + kJob + "/" + name);
    EXPECT_EQ(e.status, 404) << name;
    EXPECT_NE(e.message.find(name), std::string::npos) << e.message;
  }
  EXPECT_EQ(refusal("/api/jobs/j-12-zzzz/report.json").status, 404);  // not a job id
  EXPECT_EQ(refusal("/api/jobs/" + kJob).status, 404);
  EXPECT_EQ(refusal("/api/other").status, 404);
}

TEST(HttpRoutes, DotSegmentsPercentEncodingAndStrangeCharactersAreRefused) {
  for (const std::string& target : std::vector<std::string>{"/api/jobs/" + kJob + "/../jobs.db", "/../etc/passwd", "/assets/../../etc/passwd", "/%2e%2e/etc/passwd",
        "/api/jobs/" + kJob + "/%2e%2e%2fjobs.db", "/a//b", "/.env", "/assets/.hidden", "/a\\b", "/a b", "relative",
        "", "/caf\xc3\xa9"}) {
    const RouteError e = refusal(target);
    EXPECT_EQ(e.status, 400) << target << ": " << e.message;
    EXPECT_FALSE(e.message.empty());
  }
  EXPECT_EQ(refusal("/" + std::string(2000, 'a')).status, 400);
}

TEST(HttpRoutes, TheConsolesFilesAreSafeRelativePaths) {
  EXPECT_EQ(static_of("/"), "index.html");
  EXPECT_EQ(static_of("/?job=1"), "index.html");
  EXPECT_EQ(static_of("/assets/app-3f2a.js"), "assets/app-3f2a.js");
  EXPECT_EQ(static_of("/docs/"), "docs/index.html");
  EXPECT_TRUE(std::holds_alternative<WebSocketRequest>(*route_get("/ws")));
}

TEST(HttpRoutes, TheSessionAndTheLoginHaveTheirOwnPaths) {
  EXPECT_TRUE(std::holds_alternative<SessionRequest>(*route_get("/api/session")));
  EXPECT_EQ(route_get("/api/session/x").error().status, 404);
  EXPECT_EQ(route_post("/api/login")->route, PostRoute::login);
  EXPECT_EQ(route_post("/api/logout")->route, PostRoute::logout);
  for (const char* other : {"/api/login/", "/api/login?x=1", "/api/jobs", "/", "/api/../api/login", "/api/uploads"})
    EXPECT_EQ(route_post(other).error().status, 404) << other;
}

TEST(HttpRoutes, AnUploadNamesAPlainFileAndNothingElse) {
  const auto knob = route_post("/api/uploads?name=knob_v2.stl");
  ASSERT_TRUE(knob.has_value());
  EXPECT_EQ(knob->route, PostRoute::upload);
  EXPECT_EQ(knob->upload_name, "knob_v2.stl");
  for (const char* bad : {"/api/uploads?name=", "/api/uploads?name=../x.stl", "/api/uploads?name=a/b.stl",
                          "/api/uploads?name=.hidden.stl", "/api/uploads?name=a%2Fb.stl", "/api/uploads?name=a b.stl"})
    EXPECT_EQ(route_post(bad).error().status, 400) << bad;
}

TEST(HttpRoutes, ContentTypesFollowTheExtension) {
  EXPECT_EQ(content_type("index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(content_type("sheet-1.svg"), "image/svg+xml");
  EXPECT_EQ(content_type("stack.stl"), "model/stl");
  EXPECT_EQ(content_type("report.json"), "application/json");
  EXPECT_EQ(content_type("x.bin"), "application/octet-stream");
}

}  // namespace
}  // namespace lamina::daemon::http
