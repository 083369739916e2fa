#include "lamina/drivers/streamer.hpp"

#include "stall_watch.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <future>
#include <mutex>
#include <thread>
#include <utility>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace lamina::drivers {
namespace {

using Clock = std::chrono::steady_clock;
namespace asio = boost::asio;

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// Pacing keeps at most this much program data ahead of the wire, so a real-time byte queued
// behind it reaches the controller within it (plus one chunk).
constexpr double kPacingBacklogS = 0.015;
constexpr double kTickS = 0.005;
// While a feed hold decelerates, the status is asked 50 times a second instead of status_period_s:
// the hold watch turns the jet off once the report says the machine stands (Hold:0), and at 5 Hz
// that report came up to 200 ms late — the jet stood on the part that long (fault campaign).
constexpr double kHoldStatusPeriodS = 0.02;
constexpr double kHoldWatchAfterRequestS = 2.0;  // a hold asked for: fast reports this long at least
constexpr double kBannerWaitS = 0.5;

}  // namespace

struct Streamer::Impl {
  TransportFactory open;
  std::unique_ptr<LineProtocol> protocol;
  StreamerSettings settings;

  asio::io_context io;
  asio::executor_work_guard<asio::io_context::executor_type> guard{io.get_executor()};
  asio::steady_timer tick{io};
  std::thread thread;

  std::unique_ptr<Transport> transport;
  std::array<std::uint8_t, 4096> read_buffer{};
  std::string write_buffer;  // the bytes of the write in flight
  bool writing = false;
  std::deque<std::pair<std::string, Clock::time_point>> realtime_queue;  // ahead of program bytes
  std::size_t realtime_in_write = 0;  // how many queued real-time requests the write carries
  std::vector<Clock::time_point> realtime_in_write_times;

  // Streaming state (io thread only, mirrored under `mutex` for progress()).
  bool streaming = false, handshaking = false, loaded = false;
  LineSpan pending_span;
  LinkCallbacks callbacks;
  Clock::time_point started{}, last_heard{}, handshake_started{}, last_status_poll{}, flow_running_since{};
  Clock::time_point fast_status_until{};  // a hold is decelerating: status at kHoldStatusPeriodS
  // Lines whose bytes the transport has written (LinkProgress::lines_sent): a line taken into a
  // write that has not completed (an adapter that hangs) has not reached the controller.
  std::size_t lines_out = 0;
  std::size_t span_serial = 0;  // a write of an earlier span completing does not count in this one
  double pace_credit_bytes = 0;
  Clock::time_point pace_last{};
  std::size_t span_size = 0, first_index = 0;
  bool error_lock_pending = false;
  std::atomic<int> resets_seen{0};    // banners while not streaming (recover() waits for one)
  std::atomic<bool> flow_held{false};  // the protocol's flow_stopped(), readable off the io thread
  std::atomic<bool> awaiting_banner{false};  // read by reset() off the io thread
  Clock::time_point connected_at{};  // restarted by stale replies: the quiet period's start
  Clock::time_point opened_at{};
  detail::StallWatch stall_watch{settings.stall_margin_s};
  // Before the first line of a span: a status report, so that a controller left in feed hold
  // (or with its door open) is reported instead of being sent lines it will not run.
  bool checking_state = false;
  Clock::time_point state_check_started{};
  Clock::time_point last_doubt_poll{};

  mutable std::mutex mutex;
  std::condition_variable done_cv;
  LinkProgress shared_progress;
  std::optional<LinkOutcome> outcome;
  RealtimeLatency latency;
  double latency_sum_s = 0;

  Impl(TransportFactory f, std::unique_ptr<LineProtocol> p, StreamerSettings s)
      : open(std::move(f)), protocol(std::move(p)), settings(s) {
    thread = std::thread([this] { io.run(); });
  }
  ~Impl() {
    // Close on the io thread, then stop it outright: a tick or read handler already queued
    // when the close ran would otherwise re-arm itself and keep run() going forever.
    asio::post(io, [this] {
      tick.cancel();
      if (transport) transport->close();
      guard.reset();
      io.stop();
    });
    thread.join();
  }

  // ---- io thread ----

  void begin(LineSpan span, LinkCallbacks cbs) {
    callbacks = std::move(cbs);
    {
      std::lock_guard lock(mutex);
      outcome.reset();
      shared_progress = {};
      shared_progress.lines_total = span.lines.size();
    }
    span_size = span.lines.size();
    first_index = span.first_index;
    lines_out = 0;
    ++span_serial;
    started = last_heard = flow_running_since = Clock::now();
    streaming = true;
    loaded = false;
    if (auto bad = protocol->check_lines(span.lines, span.first_index)) return finish(std::move(*bad));
    if (!transport) {
      if (auto error = connect()) return finish(std::move(*error));
    } else if (awaiting_banner) {
      opened_at = Clock::now();  // a new job gives a chattering controller a new chance
    }
    pending_span = std::move(span);
    schedule_tick();
    if (awaiting_banner) return;  // the handshake follows the banner (or the quiet period)
    send_handshake_or_load();
  }

  // Opens the transport. Many controllers greet a new connection with their banner (a DTR
  // reset, a telnet greeting); anything sent before it may be lost or answered out of turn, so
  // the handshake waits for the banner, or for a short quiet period when none comes.
  std::optional<LinkError> connect() {
    auto opened = open(io);
    if (!opened) return opened.error();
    transport = std::move(*opened);
    spdlog::info("link: connected {}", transport->describe());
    awaiting_banner = true;
    connected_at = opened_at = Clock::now();
    read_more();
    schedule_tick();  // the ticks stopped with the lost transport; status polling resumes
    return std::nullopt;
  }

  void send_handshake_or_load() {
    const std::string hello = protocol->handshake_done() ? std::string() : protocol->handshake();
    if (!hello.empty()) {
      handshaking = true;
      handshake_started = Clock::now();
      send_realtime_bytes(hello);
    } else {
      check_state_then_load();
    }
  }

  void check_state_then_load() {
    handshaking = false;
    const std::string ask = protocol->realtime(RealtimeCommand::status);
    if (ask.empty()) return load_pending();  // a drip feed reports nothing on its line
    checking_state = true;
    state_check_started = Clock::now();
    send_realtime_bytes(ask);
  }

  // The report asked for before the first line: a held controller runs nothing we send (and
  // answers a send-response line never), so say so now.
  void on_state_checked(const ControllerStatus& status) {
    checking_state = false;
    const bool held = status.state == ControllerState::hold || status.state == ControllerState::hold_pending ||
                      status.state == ControllerState::door;
    if (!held) return load_pending();
    finish(LinkError{LinkErrorCode::controller_held,
                     fmt::format("the controller is in '{}' (a feed hold, or its door open) before the first line: "
                                 "it would run nothing; resume or reset it at the machine, then start again",
                                 status.state_text)});
  }

  void load_pending() {
    handshaking = false;
    stall_watch.load(pending_span.lines, pending_span.first_index);
    protocol->load(std::move(pending_span));
    loaded = true;
    pace_last = Clock::now();
    pace_credit_bytes = 0;
    pump();
  }

  void finish(LinkError error) { finish(std::optional<LinkError>(std::move(error))); }
  void finish(std::optional<LinkError> error) {
    if (!streaming) return;
    streaming = false;
    if (error) {
      protocol->halt();
      spdlog::warn("link: stopped: {} ({})", error->message, to_string(error->code));
    }
    LinkOutcome o;
    o.completed = !error;
    o.error = std::move(error);
    const std::size_t accepted = protocol->lines_accepted();
    o.last_accepted_index = accepted ? first_index + accepted - 1 : first_index;
    o.lines_accepted = accepted;
    publish_progress();
    // The last word to this job's owner, then forget it: the owner may be destroyed as soon as
    // wait() returns, and status reports keep coming between jobs.
    LinkCallbacks cbs = std::exchange(callbacks, LinkCallbacks{});
    if (cbs.on_progress) {
      LinkProgress p;
      {
        std::lock_guard lock(mutex);
        p = shared_progress;
      }
      cbs.on_progress(p);
    }
    {
      std::lock_guard lock(mutex);
      outcome = o;
    }
    done_cv.notify_all();
    if (cbs.on_done) cbs.on_done(o);
  }

  void read_more() {
    transport->async_read_some(read_buffer, [this](std::error_code ec, std::size_t n) {
      if (ec) {
        if (ec == std::errc::operation_canceled) return;
        const std::string what = transport ? transport->describe() : std::string("link");
        if (transport) transport->close();
        transport.reset();
        writing = false;
        finish(LinkError{LinkErrorCode::io_error, fmt::format("{}: {}", what, ec.message())});
        return;
      }
      last_heard = Clock::now();
      handle(protocol->on_received(std::string_view(reinterpret_cast<const char*>(read_buffer.data()), n)));
      flow_held = protocol->flow_stopped();
      if (transport) read_more();
    });
  }

  void handle(const std::vector<ProtocolEvent>& events) {
    for (const auto& event : events) {
      if (const auto* s = std::get_if<StatusReceived>(&event)) {
        {
          std::lock_guard lock(mutex);
          shared_progress.last_status = s->status;
        }
        publish_progress();  // acks that came before this report are counted in it
        {
          std::lock_guard lock(mutex);
          ++shared_progress.statuses_received;
        }
        if (s->status.state == ControllerState::hold_pending)
          fast_status_until = std::max(fast_status_until, Clock::now() + std::chrono::milliseconds(500));
        if (checking_state && streaming) on_state_checked(s->status);
        check_lost_acknowledgement(s->status);
        if (callbacks.on_status) callbacks.on_status(s->status);
      } else if (const auto* r = std::get_if<LineRejected>(&event)) {
        // grblHAL refuses everything after an error until an empty line: the lines already in
        // its buffer are refused (nothing moves), then the empty line clears the lock.
        error_lock_pending = true;
        send_realtime_bytes(protocol->clear_error_lock());
        finish(LinkError{LinkErrorCode::controller_error,
                         fmt::format("line {} refused: {}", r->index + 1, r->meaning)});
      } else if (const auto* a = std::get_if<ControllerAlarm>(&event)) {
        // Code 0: the protocol has no alarm numbers (a drip feed's NAK): no "alarm 0".
        finish(LinkError{LinkErrorCode::controller_alarm,
                         a->code == 0 ? a->meaning : fmt::format("alarm {}: {}", a->code, a->meaning)});
      } else if (const auto* reset = std::get_if<ControllerReset>(&event)) {
        resets_seen.fetch_add(1);
        if (awaiting_banner) {
          awaiting_banner = false;
          if (streaming) send_handshake_or_load();
          continue;
        }
        // A board that resets when its port opens (DTR on an Arduino Grbl) eats the first
        // handshake: ask again once it has printed its banner.
        if (handshaking) send_realtime_bytes(protocol->handshake());
        if (streaming && loaded)
          finish(LinkError{LinkErrorCode::controller_alarm, fmt::format("the controller reset itself ({})", reset->text)});
      } else if (const auto* info = std::get_if<ControllerInfo>(&event)) {
        std::lock_guard lock(mutex);
        if (info->planner_blocks) shared_progress.planner_blocks = info->planner_blocks;
        if (info->rx_buffer_bytes) shared_progress.rx_buffer_bytes = info->rx_buffer_bytes;
      } else if (const auto* v = std::get_if<ProtocolViolation>(&event)) {
        if (awaiting_banner) {
          // We have not said a word on this connection yet: an `ok` for a host that died (the
          // controller drains the queue it was given) is not ours. Wait for quiet again.
          spdlog::info("link: ignored before the handshake (left from an earlier connection): {}", v->what);
          connected_at = Clock::now();
          continue;
        }
        finish(LinkError{LinkErrorCode::protocol_error, v->what});
      }
    }
    if (handshaking && protocol->handshake_done()) check_state_then_load();
    if (streaming && loaded && protocol->finished()) finish(std::nullopt);
    publish_progress();
    pump();
  }

  // Idle with lines unanswered: a lost `ok`, a line that never arrived whole, or a controller
  // that stopped reading — unless the line waited on is a dwell or a sync (stall_watch.hpp).
  void check_lost_acknowledgement(const ControllerStatus& status) {
    if (!streaming || !loaded) return;
    const detail::LinkCounts counts{protocol->lines_sent(), protocol->lines_accepted(), protocol->unanswered()};
    const double now_s = std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
    if (auto error = stall_watch.on_status(status, now_s, counts)) finish(std::move(*error));
  }

  void send_realtime_bytes(std::string bytes) {
    if (bytes.empty()) return;
    realtime_queue.emplace_back(std::move(bytes), Clock::now());
    pump();
  }

  // One write at a time: queued real-time bytes first, then paced program bytes.
  void pump() {
    if (writing || !transport) return;
    write_buffer.clear();
    realtime_in_write_times.clear();
    while (!realtime_queue.empty()) {
      write_buffer += realtime_queue.front().first;
      realtime_in_write_times.push_back(realtime_queue.front().second);
      realtime_queue.pop_front();
    }
    if (streaming && loaded) write_buffer += paced_program_bytes();
    if (write_buffer.empty()) return;
    writing = true;
    const std::size_t lines_in_write = protocol->lines_sent(), serial = span_serial;
    transport->async_write(std::span(reinterpret_cast<const std::uint8_t*>(write_buffer.data()), write_buffer.size()),
                           [this, lines_in_write, serial](std::error_code ec, std::size_t n) {
                             writing = false;
                             const auto now = Clock::now();
                             for (auto t : realtime_in_write_times) record_latency(seconds_between(t, now));
                             if (ec) {
                               if (ec == std::errc::operation_canceled) return;
                               finish(LinkError{LinkErrorCode::io_error, fmt::format("write: {}", ec.message())});
                               return;
                             }
                             {
                               std::lock_guard lock(mutex);
                               shared_progress.bytes_sent += n;
                               // Out now, not at the next answer: a controller that stalls answers nothing.
                               if (serial == span_serial) lines_out = std::max(lines_out, lines_in_write);
                               shared_progress.lines_sent = std::max(lines_out, protocol->lines_accepted());
                             }
                             // A drip feed is done when its last byte is out: no ack will come.
                             if (streaming && loaded && protocol->finished()) {
                               publish_progress();
                               finish(std::nullopt);
                             }
                             pump();
                           });
  }

  std::string paced_program_bytes() {
    if (settings.pace_bytes_per_s <= 0) return protocol->take_sendable();
    const auto now = Clock::now();
    double backlog_bytes = settings.pace_bytes_per_s * kPacingBacklogS;
    if (const std::size_t cap = protocol->max_backlog_bytes(); cap > 0)
      backlog_bytes = std::min(backlog_bytes, static_cast<double>(cap));
    pace_credit_bytes =
        std::min(backlog_bytes, pace_credit_bytes + seconds_between(pace_last, now) * settings.pace_bytes_per_s);
    pace_last = now;
    if (pace_credit_bytes < 1) return {};
    // Whole lines up to the credit; a line longer than the credit goes alone and takes the
    // credit negative rather than being split: the backlog bound is then credit + one line.
    // (Handing out everything the controller had room for — a whole window after a resume —
    // let 1 KiB queue ahead of a feed hold: 88 ms at 115200 baud, bench/hold_latency.)
    std::string bytes = protocol->take_sendable(static_cast<std::size_t>(pace_credit_bytes));
    pace_credit_bytes -= static_cast<double>(bytes.size());
    return bytes;
  }

  void record_latency(double s) {
    std::lock_guard lock(mutex);
    latency.max_s = std::max(latency.max_s, s);
    latency_sum_s += s;
    ++latency.count;
    latency.mean_s = latency_sum_s / static_cast<double>(latency.count);
  }

  void publish_progress() {
    std::lock_guard lock(mutex);
    shared_progress.lines_sent = std::max(lines_out, protocol->lines_accepted());
    shared_progress.lines_accepted = protocol->lines_accepted();
    shared_progress.seconds = seconds_between(started, Clock::now());
  }

  // Without status polling, a quiet controller may be busy (a long move, a dwell, the drain
  // before a sync) or dead: ask it before the silence timeout decides. A live one answers,
  // and its report goes through the stall rule above.
  void poll_when_in_doubt(Clock::time_point now) {
    if (settings.status_period_s > 0 || !streaming || !loaded) return;
    if (protocol->lines_sent() == protocol->lines_accepted()) return;
    if (seconds_between(last_heard, now) < settings.silence_timeout_s / 4) return;
    if (seconds_between(last_doubt_poll, now) < settings.silence_timeout_s / 4) return;
    last_doubt_poll = now;
    send_realtime_bytes(protocol->realtime(RealtimeCommand::status));
  }

  // A dwell is silent by design: the silence allowed grows by the dwell of the line waited on.
  double silence_allowed_s() const {
    return stall_watch.silence_allowed_s(settings.silence_timeout_s, protocol->lines_accepted());
  }

  // Paced with a small backlog bound (XON/XOFF), the wire drains the bound quicker than the
  // usual tick: wake up twice per bound so the link stays busy (at least every 0.5 ms).
  double tick_period_s() const {
    const std::size_t cap = protocol->max_backlog_bytes();
    if (cap == 0 || settings.pace_bytes_per_s <= 0) return kTickS;
    return std::clamp(static_cast<double>(cap) / settings.pace_bytes_per_s / 2, 0.0005, kTickS);
  }

  void schedule_tick() {
    tick.expires_after(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(tick_period_s())));
    tick.async_wait([this](boost::system::error_code ec) {
      if (ec) return;
      on_tick();
      if (transport || streaming) schedule_tick();  // status keeps coming between jobs
    });
  }

  void on_tick() {
    const auto now = Clock::now();
    if (awaiting_banner && streaming && seconds_between(opened_at, now) > settings.handshake_timeout_s) {
      finish(LinkError{LinkErrorCode::timeout,
                       fmt::format("{}: the controller kept sending replies nobody asked for for {} s",
                                   transport ? transport->describe() : "link", settings.handshake_timeout_s)});
      return;
    }
    if (awaiting_banner && seconds_between(connected_at, now) > kBannerWaitS) {
      awaiting_banner = false;
      if (streaming) send_handshake_or_load();
    }
    if (handshaking && seconds_between(handshake_started, now) > settings.handshake_timeout_s) {
      finish(LinkError{LinkErrorCode::timeout,
                       fmt::format("{}: no answer to the handshake within {} s",
                                   transport ? transport->describe() : "link", settings.handshake_timeout_s)});
      return;
    }
    if (checking_state && streaming && seconds_between(state_check_started, now) > settings.handshake_timeout_s) {
      finish(LinkError{LinkErrorCode::timeout, fmt::format("{}: no status report within {} s before the first line",
                                                           transport ? transport->describe() : "link",
                                                           settings.handshake_timeout_s)});
      return;
    }
    const double status_period_s =
        now < fast_status_until ? std::min(settings.status_period_s, kHoldStatusPeriodS) : settings.status_period_s;
    if (settings.status_period_s > 0 && seconds_between(last_status_poll, now) >= status_period_s) {
      last_status_poll = now;
      send_realtime_bytes(protocol->realtime(RealtimeCommand::status));
    }
    poll_when_in_doubt(now);
    if (!protocol->flow_stopped()) flow_running_since = now;
    if (streaming && loaded && seconds_between(flow_running_since, now) > settings.silence_timeout_s) {
      finish(LinkError{LinkErrorCode::timeout, fmt::format("the controller has held the line (XOFF) for {} s",
                                                           settings.silence_timeout_s)});
      return;
    }
    const bool in_flight = protocol->lines_sent() > protocol->lines_accepted();
    if (streaming && loaded && in_flight && seconds_between(last_heard, now) > silence_allowed_s()) {
      finish(LinkError{LinkErrorCode::timeout,
                       fmt::format("nothing heard for {} s with {} line(s) in flight", settings.silence_timeout_s,
                                   protocol->lines_sent() - protocol->lines_accepted())});
      return;
    }
    if (callbacks.on_progress) {
      LinkProgress p;
      {
        std::lock_guard lock(mutex);
        p = shared_progress;
      }
      callbacks.on_progress(p);
    }
    pump();
  }
};

Streamer::Streamer(TransportFactory open, std::unique_ptr<LineProtocol> protocol, StreamerSettings settings)
    : impl_(std::make_unique<Impl>(std::move(open), std::move(protocol), settings)) {}

Streamer::~Streamer() = default;

std::optional<LinkError> Streamer::check_lines(const std::vector<std::string>& lines, std::size_t first_index) const {
  return impl_->protocol->check_lines(lines, first_index);
}

void Streamer::start(LineSpan span, LinkCallbacks callbacks) {
  {
    std::lock_guard lock(impl_->mutex);  // so a wait() right after this waits for this run
    impl_->outcome.reset();
  }
  asio::post(impl_->io, [impl = impl_.get(), span = std::move(span), callbacks = std::move(callbacks)]() mutable {
    impl->begin(std::move(span), std::move(callbacks));
  });
}

void Streamer::request(RealtimeCommand command) {
  const auto requested = Clock::now();
  asio::post(impl_->io, [impl = impl_.get(), command, requested] {
    std::string bytes = impl->protocol->realtime(command);
    if (bytes.empty()) return;
    if (command == RealtimeCommand::feed_hold)
      impl->fast_status_until = std::max(impl->fast_status_until, requested + std::chrono::duration_cast<Clock::duration>(
                                                                                  std::chrono::duration<double>(kHoldWatchAfterRequestS)));
    impl->realtime_queue.emplace_back(std::move(bytes), requested);
    impl->pump();
  });
}

void Streamer::stop(LinkError why) {
  asio::post(impl_->io, [impl = impl_.get(), why = std::move(why)]() mutable { impl->finish(std::move(why)); });
}

LinkProgress Streamer::progress() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->shared_progress;
}

std::optional<LinkOutcome> Streamer::wait(double timeout_s) {
  std::unique_lock lock(impl_->mutex);
  if (!impl_->done_cv.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return impl_->outcome.has_value(); }))
    return std::nullopt;
  return impl_->outcome;
}

bool Streamer::can_reset() const { return !impl_->protocol->realtime(RealtimeCommand::reset).empty(); }

std::optional<LinkError> Streamer::reset(double timeout_s) {
  if (!can_reset()) return LinkError{LinkErrorCode::bad_request, "this protocol has no soft reset on its line"};
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  // A link lost to an unplug is opened again first (the port may be back): a reset written to
  // no port reaches nobody, and a resume after a replug always failed on it.
  std::promise<std::optional<LinkError>> opened;
  auto reopened = opened.get_future();
  asio::post(impl_->io, [impl = impl_.get(), &opened] {
    opened.set_value(impl->transport ? std::nullopt : impl->connect());
  });
  if (auto error = reopened.get()) return error;
  // A board that greets the new connection does so first; our reset's banner must not be
  // mistaken for that one (or that one for ours).
  while (impl_->awaiting_banner.load() && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const int before = impl_->resets_seen.load();
  request(RealtimeCommand::reset);
  // The controller answers a reset with its banner; give it until the deadline.
  while (impl_->resets_seen.load() == before && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (impl_->resets_seen.load() == before) return LinkError{LinkErrorCode::timeout, "no banner after the soft reset"};
  return std::nullopt;
}

std::optional<LinkError> Streamer::recover(double timeout_s) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  if (can_reset()) {
    if (auto error = reset(timeout_s)) return error;
  } else {
    // A drip feed is reset from the panel or the PLC, not over its line; it then releases the
    // line (SYN, then DC1). Streaming before that would run into the XOFF of the held buffer.
    while (impl_->flow_held.load() && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (impl_->flow_held.load())
      return LinkError{LinkErrorCode::timeout, "the controller still holds the line (XOFF) after its reset"};
  }
  const auto unlock = impl_->protocol->unlock_lines();
  if (unlock.empty()) return std::nullopt;
  start(LineSpan{unlock, 0}, {});
  const double left_s = std::max(0.1, std::chrono::duration<double>(deadline - Clock::now()).count());
  const auto outcome = wait(left_s);
  if (!outcome) return LinkError{LinkErrorCode::timeout, "no answer to the unlock"};
  return outcome->error;
}

RealtimeLatency Streamer::realtime_latency() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->latency;
}

}  // namespace lamina::drivers
