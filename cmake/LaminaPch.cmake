# Precompiled headers. Most translation units parse the same heavy third-party headers
# (Boost.Asio, nlohmann/json, spdlog, CLI11, Eigen, GoogleTest): 4-12 s of a 10-27 s compile
# (daemon/laminad/main.cpp: 13.1 of 26.6 s; docs/performance.md, "Build and CI"). A target's
# precompiled header parses them once for all of its files. -DLAMINA_PCH=OFF builds without,
# which also checks that every file includes what it uses.
option(LAMINA_PCH "Precompile the common third-party headers, once per target" ON)

set(LAMINA_PCH_STD <algorithm> <cmath> <cstdint> <expected> <functional> <map> <memory> <optional> <string>
    <string_view> <vector> <fmt/format.h>)
set(LAMINA_PCH_EIGEN <Eigen/Core> <Eigen/Geometry>)
set(LAMINA_PCH_JSON <nlohmann/json.hpp>)
set(LAMINA_PCH_ASIO <boost/asio/io_context.hpp> <boost/asio/post.hpp> <boost/asio/steady_timer.hpp>
    <boost/asio/ip/tcp.hpp> <boost/asio/local/stream_protocol.hpp>)
set(LAMINA_PCH_LOG <spdlog/spdlog.h>)
set(LAMINA_PCH_CLI <CLI/CLI.hpp>)
set(LAMINA_PCH_GTEST <gtest/gtest.h>)

# lamina_precompile(target STD EIGEN …): the named header sets above, for `target` only.
function(lamina_precompile target)
  if(NOT LAMINA_PCH)
    return()
  endif()
  set(headers)
  foreach(set_name IN LISTS ARGN)
    list(APPEND headers ${LAMINA_PCH_${set_name}})
  endforeach()
  target_precompile_headers(${target} PRIVATE ${headers})
endfunction()
