#pragma once
// The JSON-RPC 2.0 framing of rpc_server, without sockets: turning one received line into a
// request (or the error reply it deserves), and building the reply/notification lines.
// Pure functions, so the connection code stays about I/O.
#include <cstddef>
#include <expected>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "lamina/daemon/rpc_server.hpp"

namespace lamina::daemon::rpc_detail {

// Sent (then the connection closed) to a client past settings.max_clients. Implementation-
// defined server error range of JSON-RPC; never returned by a handler.
inline constexpr int too_many_clients = -32000;

// Requests nested deeper than this are refused: nlohmann parses and frees deep values without
// recursion, but copying or dumping them recurses, and a handler that copies its params must not
// be able to overflow the io thread's stack because of a hostile line.
inline constexpr int max_nesting_depth = 64;

// A line that is not a valid request: the reply to send (id is null when it could not be read).
struct InvalidRequest {
  nlohmann::json id;
  RpcError error;
};

// Parses and validates one line (without its '\n'). Batches (a top-level array) are refused with
// -32600: no client of laminad needs them, and a batch's replies would have to be gathered across
// handlers, which buys nothing on a connection that already pipelines.
std::expected<RpcRequest, InvalidRequest> parse_request(std::string_view line);

// TCP requests: params must be an object whose "token" equals `expected` (compared in constant
// time); the token is removed so that handlers never see (or log) it.
std::expected<void, RpcError> check_and_strip_token(nlohmann::json& params, std::string_view expected);
bool tokens_equal(std::string_view given, std::string_view expected);

// Complete lines, '\n' included. Strings that are not valid UTF-8 (a handler's result built from
// raw bytes) are replaced rather than thrown on: a reply must always be producible.
std::string result_line(const nlohmann::json& id, const nlohmann::json& result);
std::string error_line(const nlohmann::json& id, const RpcError& error);
std::string notification_line(const std::string& method, const nlohmann::json& params);

}  // namespace lamina::daemon::rpc_detail
