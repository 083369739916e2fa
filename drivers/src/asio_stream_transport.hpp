#pragma once
// Internal: a Transport over any Asio byte stream (serial_port, posix::stream_descriptor,
// ip::tcp::socket). The three transports differ only in how they open and in how they let go of
// the descriptor, so the Asio plumbing lives here once.
//
// Threads: the object is built on the caller's thread (open_*), before any operation is pending.
// From then on async_read_some, async_write and close() must be called from the thread that runs
// the io_context (or be posted to it): Asio I/O objects are not thread-safe. Completion handlers
// run on that thread. One read and one write may be pending at a time.
#include <boost/asio/buffer.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>

#include <string>
#include <utility>

#include "lamina/drivers/transport.hpp"

namespace lamina::drivers::detail {

template <class Stream>
class AsioStreamTransport : public Transport {
 public:
  AsioStreamTransport(Stream stream, std::string description)
      : stream_(std::move(stream)), description_(std::move(description)) {}
  ~AsioStreamTransport() override { close_stream(); }

  void async_read_some(std::span<std::uint8_t> buffer, ReadHandler handler) override {
    // The handler captures nothing of ours: after close() or destruction Asio still delivers
    // operation_aborted to it without touching this object.
    stream_.async_read_some(boost::asio::buffer(buffer.data(), buffer.size()),
                            [h = std::move(handler)](const boost::system::error_code& ec, std::size_t n) {
                              h(std::error_code(ec), n);
                            });
  }

  void async_write(std::span<const std::uint8_t> data, WriteHandler handler) override {
    boost::asio::async_write(stream_, boost::asio::buffer(data.data(), data.size()),
                             [h = std::move(handler)](const boost::system::error_code& ec, std::size_t n) {
                               h(std::error_code(ec), n);
                             });
  }

  void close() override { close_stream(); }
  std::string describe() const override { return description_; }

 protected:
  Stream& stream() { return stream_; }

  // Cancels pending operations (their handlers get operation_aborted) and closes; a second call
  // finds the stream closed and does nothing. Overridden where the descriptor is not ours.
  virtual void close_stream() {
    if (!stream_.is_open()) return;
    boost::system::error_code ignored;
    stream_.cancel(ignored);
    stream_.close(ignored);
  }

 private:
  Stream stream_;
  std::string description_;
};

}  // namespace lamina::drivers::detail
