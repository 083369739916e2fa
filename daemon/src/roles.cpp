#include "lamina/daemon/roles.hpp"

namespace lamina::daemon {

const char* role_name(Role role) {
  switch (role) {
    case Role::viewer: return "viewer";
    case Role::machine_operator: return "operator";
    case Role::engineer: break;
  }
  return "engineer";
}

const char* role_with_article(Role role) {
  switch (role) {
    case Role::viewer: return "a viewer";
    case Role::machine_operator: return "an operator";
    case Role::engineer: break;
  }
  return "an engineer";
}

std::optional<Role> role_from_name(std::string_view name) {
  for (Role r : {Role::viewer, Role::machine_operator, Role::engineer})
    if (name == role_name(r)) return r;
  return std::nullopt;
}

}  // namespace lamina::daemon
