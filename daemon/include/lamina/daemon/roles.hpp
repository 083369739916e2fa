#pragma once
// What a client of laminad may do (docs/web.md): a viewer sees everything; an operator also
// holds, resumes and aborts the machine, confirms sheets and resumes interrupted jobs; an
// engineer also submits, cancels and uploads. Unix-socket and TCP clients are engineers: they
// hold the socket's permissions or the token. Console users have the role their entry names.
#include <cstdint>
#include <optional>
#include <string_view>

namespace lamina::daemon {

enum class Role : std::uint8_t { viewer, machine_operator, engineer };  // each may do what the one before may

const char* role_name(Role role);  // "viewer", "operator", "engineer"
const char* role_with_article(Role role);  // "a viewer", "an operator", "an engineer" (refusals)
std::optional<Role> role_from_name(std::string_view name);

}  // namespace lamina::daemon
