// RpcTransport over a stream socket (Unix or TCP): read what arrives, write lines gathered.
#include <vector>

#include <boost/asio/buffer.hpp>
#include <boost/asio/write.hpp>

#include "rpc_transport.hpp"

namespace lamina::daemon {
namespace {

constexpr std::size_t read_chunk_bytes = 64 * 1024;

class StreamTransport final : public RpcTransport {
 public:
  using Socket = boost::asio::generic::stream_protocol::socket;
  explicit StreamTransport(Socket socket) : socket_(std::move(socket)), chunk_(read_chunk_bytes) {}

  boost::asio::any_io_executor executor() override { return socket_.get_executor(); }

  void async_read(ReadHandler handler) override {
    socket_.async_read_some(boost::asio::buffer(chunk_),
                            [this, handler = std::move(handler)](const boost::system::error_code& error, std::size_t size) {
                              handler(error, std::string_view(chunk_.data(), size));
                            });
  }

  void async_write(std::span<const Line> lines, WriteHandler handler) override {
    // Everything queued goes out in one gathered write: a pipelining client gets its replies in
    // few system calls.
    buffers_.clear();
    for (const auto& line : lines) buffers_.push_back(boost::asio::buffer(*line));
    boost::asio::async_write(socket_, buffers_,
                             [handler = std::move(handler)](const boost::system::error_code& error, std::size_t) {
                               handler(error);
                             });
  }

  void shutdown_send() override {
    boost::system::error_code ignored;
    socket_.shutdown(Socket::shutdown_send, ignored);
  }

  void close() override {
    boost::system::error_code ignored;
    socket_.close(ignored);
  }

 private:
  // The connection owns the transport and outlives every operation on it (its handlers hold it),
  // so the read handler may use `this`.
  Socket socket_;
  std::vector<char> chunk_;
  std::vector<boost::asio::const_buffer> buffers_;
};

}  // namespace

std::unique_ptr<RpcTransport> make_stream_transport(boost::asio::generic::stream_protocol::socket socket) {
  return std::make_unique<StreamTransport>(std::move(socket));
}

}  // namespace lamina::daemon
