#include "rpc_protocol.hpp"

#include <utility>

#include <fmt/format.h>

namespace lamina::daemon::rpc_detail {
namespace {

using nlohmann::json;

std::unexpected<InvalidRequest> invalid(json id, std::string message) {
  return std::unexpected(InvalidRequest{std::move(id), RpcError{rpc_code::invalid_request, std::move(message), {}}});
}

bool valid_id(const json& id) { return id.is_null() || id.is_string() || id.is_number(); }

std::string dump_line(const json& message) {
  std::string line = message.dump(-1, ' ', false, json::error_handler_t::replace);
  line.push_back('\n');
  return line;
}

}  // namespace

namespace {

// Deeper than max_nesting_depth, found by scanning brackets outside strings before any value is
// built: a MiB of '[' used to be parsed into a million nested arrays first (0.4 s per line on
// the io thread; 100 such clients held it for 40 s) and refused only afterwards.
bool nested_too_deep(std::string_view line) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (const char c : line) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_nesting_depth) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

}  // namespace

std::expected<RpcRequest, InvalidRequest> parse_request(std::string_view line) {
  if (nested_too_deep(line)) return invalid(nullptr, fmt::format("nested deeper than {} levels", max_nesting_depth));
  json message = json::parse(line.begin(), line.end(), nullptr, /*allow_exceptions=*/false);
  if (message.is_discarded())
    return std::unexpected(InvalidRequest{nullptr, RpcError{rpc_code::parse_error, "parse error", {}}});
  if (message.is_array()) return invalid(nullptr, "batches are not supported");
  if (!message.is_object()) return invalid(nullptr, "a request must be a JSON object");

  // The id is echoed in the error replies below when it is usable, so the client can match them.
  const auto id_it = message.find("id");
  const bool has_id = id_it != message.end();
  json id = has_id && valid_id(*id_it) ? *id_it : json(nullptr);
  if (has_id && !valid_id(*id_it)) return invalid(nullptr, "id must be a string, a number or null");

  const auto version = message.find("jsonrpc");
  if (version == message.end() || !version->is_string() || version->get_ref<const std::string&>() != "2.0")
    return invalid(std::move(id), R"(missing "jsonrpc": "2.0")");
  const auto method = message.find("method");
  if (method == message.end() || !method->is_string()) return invalid(std::move(id), "method must be a string");

  RpcRequest request;
  request.is_notification = !has_id;
  request.method = method->get<std::string>();
  if (const auto params = message.find("params"); params != message.end()) {
    if (!params->is_object() && !params->is_array())
      return invalid(std::move(id), "params must be an object or an array");
    request.params = std::move(*params);
  } else {
    request.params = json::object();
  }
  request.id = std::move(id);
  return request;
}

bool tokens_equal(std::string_view given, std::string_view expected) {
  // Every byte of the expected token is looked at whatever the input, so the time taken does not
  // tell how long a matching prefix was.
  unsigned difference = given.size() == expected.size() ? 0U : 1U;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const unsigned char g = i < given.size() ? static_cast<unsigned char>(given[i]) : 0U;
    difference |= g ^ static_cast<unsigned char>(expected[i]);
  }
  return difference == 0U && !expected.empty();
}

std::expected<void, RpcError> check_and_strip_token(json& params, std::string_view expected) {
  const RpcError unauthorized{rpc_code::unauthorized, "unauthorized", {}};
  if (!params.is_object()) return std::unexpected(unauthorized);
  const auto token = params.find("token");
  if (token == params.end() || !token->is_string() || !tokens_equal(token->get_ref<const std::string&>(), expected))
    return std::unexpected(unauthorized);
  params.erase(token);
  return {};
}

std::string result_line(const json& id, const json& result) {
  return dump_line(json{{"jsonrpc", "2.0"}, {"id", id}, {"result", result}});
}

std::string error_line(const json& id, const RpcError& error) {
  json body{{"code", error.code}, {"message", error.message}};
  if (!error.data.is_null()) body["data"] = error.data;
  return dump_line(json{{"jsonrpc", "2.0"}, {"id", id}, {"error", std::move(body)}});
}

std::string notification_line(const std::string& method, const json& params) {
  return dump_line(json{{"jsonrpc", "2.0"}, {"method", method}, {"params", params}});
}

}  // namespace lamina::daemon::rpc_detail
