// ModbusBlockLink: one thread owns the libmodbus context for the link's lifetime. A job (start)
// streams blocks through the PLC's mailbox; between mailbox writes the thread serves real-time
// requests first (coils 4/5/6 or a status read), so they jump the queue. Every read of the 20
// CNC input registers doubles as the status, the ack check and the room check.
#include "lamina/drivers/modbus_block_link.hpp"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "lamina/drivers/line_wait.hpp"
#include "mailbox_codec.hpp"
#include "modbus_client.hpp"
#include "plc_map.hpp"

namespace lamina::drivers {
namespace pm = plc_map;
using Clock = std::chrono::steady_clock;

namespace {
constexpr auto kPollInterval = std::chrono::milliseconds(2);  // ack / room polling while streaming
Clock::duration seconds(double s) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); }
// Every block must fit the mailbox and be one line (check_mailbox_block).
std::optional<LinkError> check_program_lines(const std::vector<std::string>& lines, std::size_t first_index) {
  for (std::size_t i = 0; i < lines.size(); ++i)
    if (auto bad = check_mailbox_block(first_index + i, lines[i])) return bad;
  return std::nullopt;
}

}  // namespace

struct ModbusBlockLink::Impl {
  Impl(ModbusBlockSettings s, std::unique_ptr<RegisterBus> b)
      : settings(std::move(s)),
        log(driver_logger("modbus-link")),
        bus(b ? std::move(b) : make_modbus_bus(settings.plc, "modbus-link")),
        client(*bus) {
    client.set_abort([this] { return shutting_down.load() || stop_requested.load(); });
    thread = std::thread([this] { run(); });
  }

  ModbusBlockSettings settings;
  std::shared_ptr<spdlog::logger> log;
  std::unique_ptr<RegisterBus> bus;  // the PLC (Modbus TCP unless a test gives its own)
  RegisterBus& client;               // the thread's only
  std::thread thread;

  mutable std::mutex mutex;
  std::condition_variable wake;  // the thread waits for work; wait() waits for outcomes
  std::atomic<bool> shutting_down{false};
  std::atomic<bool> stop_requested{false};
  std::optional<LinkError> stop_reason;
  std::deque<RealtimeCommand> realtime;
  std::optional<LineSpan> pending_job;
  LinkCallbacks callbacks;
  bool running = false;  // a job started and not finished
  LinkProgress progress;
  Clock::time_point job_start;
  std::optional<LinkOutcome> outcome;

  // Thread-only.
  std::uint16_t seq = 0;
  Clock::time_point next_status;
  std::vector<std::uint16_t> cnc;  // the last read of input registers 0…19

  void run() {
    while (!shutting_down) {
      serve_realtime();
      std::optional<LineSpan> job;
      {
        std::lock_guard lock(mutex);
        if (pending_job) job.swap(pending_job);
      }
      if (job) {
        run_job(std::move(*job));
        continue;
      }
      // Idle: keep the status fresh while connected (a dead PLC is not retried until needed).
      if (client.connected() && Clock::now() >= next_status) (void)read_cnc(true);
      const auto deadline = client.connected() ? next_status : Clock::now() + std::chrono::seconds(1);
      std::unique_lock lock(mutex);
      wake.wait_until(lock, deadline, [this] { return shutting_down || pending_job || !realtime.empty(); });
    }
  }

  // Reads the CNC registers; publishes a status when due (or when asked).
  std::expected<void, LinkError> read_cnc(bool publish_now = false) {
    auto regs = client.read_input_registers(0, pm::kInCount);
    if (!regs) return std::unexpected(regs.error());
    cnc = std::move(*regs);
    if (publish_now || Clock::now() >= next_status) {
      next_status = Clock::now() + seconds(settings.status_period_s);
      const ControllerStatus status = decode_cnc_status(cnc);
      std::function<void(const ControllerStatus&)> on_status;
      std::function<void(const LinkProgress&)> on_progress;
      LinkProgress snapshot;
      {
        std::lock_guard lock(mutex);
        progress.last_status = status;
        ++progress.statuses_received;
        if (running) progress.seconds = std::chrono::duration<double>(Clock::now() - job_start).count();
        on_status = callbacks.on_status;
        on_progress = running ? callbacks.on_progress : nullptr;
        snapshot = progress;
      }
      if (on_status) on_status(status);
      if (on_progress) on_progress(snapshot);
    }
    return {};
  }

  // Real-time commands ahead of the next mailbox write: the PLC's CNC push buttons.
  void serve_realtime() {
    while (true) {
      RealtimeCommand command;
      {
        std::lock_guard lock(mutex);
        if (realtime.empty()) return;
        command = realtime.front();
        realtime.pop_front();
      }
      std::expected<void, LinkError> r;
      switch (command) {
        case RealtimeCommand::status: r = read_cnc(true); break;
        case RealtimeCommand::feed_hold: r = client.write_bit(pm::kCoilCncFeedHold, true); break;
        case RealtimeCommand::resume: r = client.write_bit(pm::kCoilCncCycleStart, true); break;
        case RealtimeCommand::reset: r = client.write_bit(pm::kCoilCncReset, true); break;
      }
      if (!r) log->error("real-time command failed: {}", r.error().message);  // a job fails on its next read
    }
  }

  void finish(std::optional<LinkError> error, std::size_t first_index) {
    LinkOutcome result;
    std::function<void(const LinkOutcome&)> on_done;
    {
      std::lock_guard lock(mutex);
      result.completed = !error && progress.lines_accepted == progress.lines_total;
      result.error = std::move(error);
      result.last_accepted_index = progress.lines_accepted > 0 ? first_index + progress.lines_accepted - 1 : first_index;
      progress.seconds = std::chrono::duration<double>(Clock::now() - job_start).count();
      outcome = result;
      running = false;
      stop_requested = false;
      stop_reason.reset();
      on_done = callbacks.on_done;
      // The job that gave these is over: its owner may be gone before the next status report.
      callbacks = {};
    }
    if (result.error) log->error("streaming stopped: {}", result.error->message);
    if (on_done) on_done(result);
    wake.notify_all();
  }

  std::optional<LinkError> stopped() {
    if (!stop_requested) return std::nullopt;
    std::lock_guard lock(mutex);
    return stop_reason.value_or(LinkError{LinkErrorCode::cancelled, "stopped"});
  }

  LinkError at_line(const LinkError& e, std::size_t index, const std::string& line) {
    return {e.code, fmt::format("{}: {}", describe_line(index, line), e.message)};
  }

  // Before the first block: continue after the PLC's last sequence number (a seq equal to it
  // would be ignored and a stale ack taken for ours), and clear a mailbox alarm left from before.
  std::expected<void, LinkError> begin_job() {
    auto last = client.read_registers(pm::kHoldMailboxSeq, 1);
    if (!last) return std::unexpected(last.error());
    seq = (*last)[0];
    if (auto r = read_cnc(true); !r) return r;
    const int alarm = cnc[pm::kInAlarmCode];
    if (alarm == pm::kAlarmMailboxOverrun || alarm == pm::kAlarmMailboxBadBlock) {
      log->warn("PLC alarm {} ({}) left from an earlier job: pressing alarm_reset", alarm, pm::alarm_name(alarm));
      if (auto r = client.write_bit(pm::kCoilAlarmReset, true); !r) return r;
      return read_cnc();
    }
    return {};
  }

  // Why the job cannot go on, from the last CNC read (nullopt: it can).
  std::optional<LinkError> cnc_trouble(std::size_t index, const std::string& line) {
    if (cnc[pm::kInCncState] == 4)
      return LinkError{LinkErrorCode::controller_alarm,
                       fmt::format("CNC in alarm (cnc_state 4, PLC alarm code {}) at {}", cnc[pm::kInAlarmCode],
                                   describe_line(index, line))};
    const int alarm = cnc[pm::kInAlarmCode];
    if (alarm == pm::kAlarmMailboxBadBlock)
      return LinkError{LinkErrorCode::controller_error,
                       fmt::format("the CNC refused {} (PLC alarm 4, mailbox bad block)", describe_line(index, line))};
    if (alarm == pm::kAlarmMailboxOverrun)
      return LinkError{LinkErrorCode::modbus_error,
                       fmt::format("PLC alarm 3 (mailbox overrun) at {}", describe_line(index, line))};
    return std::nullopt;
  }

  void run_job(LineSpan span) {
    if (auto bad = check_program_lines(span.lines, span.first_index)) return finish(bad, span.first_index);
    if (auto r = begin_job(); !r) return finish(r.error(), span.first_index);

    Clock::time_point dwell_ends{};  // when the last dwell the CNC took is over
    for (std::size_t i = 0; i < span.lines.size(); ++i) {
      const std::size_t index = span.first_index + i;
      const std::string& line = span.lines[i];
      // Room in the CNC's queue (a hold may keep it full for as long as the operator likes).
      while (cnc[pm::kInMailboxFree] == 0) {
        if (auto e = stopped()) return finish(e, span.first_index);
        if (auto e = cnc_trouble(index, line)) return finish(e, span.first_index);
        serve_realtime();
        std::this_thread::sleep_for(kPollInterval);
        if (auto r = read_cnc(); !r) return finish(at_line(r.error(), index, line), span.first_index);
      }
      if (auto e = stopped()) return finish(e, span.first_index);
      serve_realtime();  // real-time commands jump the queue
      seq = next_mailbox_seq(seq);
      const auto regs = encode_mailbox_block(seq, line);
      if (auto r = client.write_registers(pm::kHoldMailboxSeq, regs); !r)
        return finish(at_line(r.error(), index, line), span.first_index);
      {
        std::lock_guard lock(mutex);
        ++progress.lines_sent;
        progress.bytes_sent += line.size();
      }
      // The acknowledge. A CNC that is running or held has not lost the block: it takes a jet
      // M-code, a program end or a dwell only once its queue has drained (the planner sync),
      // which may take minutes of cutting, and a hold keeps it for as long as the operator
      // likes. The timeout counts only while it stands idle with the block untaken — and a
      // controller that dwells stands idle on purpose: a dwell starts when its block is taken
      // (after the drain), so until its P has passed no block behind it is overdue.
      const auto ack_deadline = [&] { return std::max(Clock::now(), dwell_ends) + seconds(settings.ack_timeout_s); };
      auto deadline = ack_deadline();
      while (true) {
        if (auto r = read_cnc(); !r) return finish(at_line(r.error(), index, line), span.first_index);
        if (cnc[pm::kInMailboxAck] == seq) break;
        if (const int state = cnc[pm::kInCncState]; state >= 1 && state <= 3) deadline = ack_deadline();
        if (auto e = cnc_trouble(index, line)) return finish(e, span.first_index);
        if (auto e = stopped()) return finish(e, span.first_index);
        if (Clock::now() >= deadline)
          return finish(LinkError{LinkErrorCode::timeout,
                                  fmt::format("{} not acknowledged within {} s (mailbox_ack {}, seq {})",
                                              describe_line(index, line), settings.ack_timeout_s,
                                              cnc[pm::kInMailboxAck], seq)},
                        span.first_index);
        serve_realtime();
        std::this_thread::sleep_for(kPollInterval);
      }
      if (const double dwell_s = grbl_line_wait(line).dwell_s; dwell_s > 0)
        dwell_ends = Clock::now() + seconds(dwell_s);
      std::lock_guard lock(mutex);
      ++progress.lines_accepted;
    }
    finish(std::nullopt, span.first_index);
  }
};

std::optional<LinkError> ModbusBlockLink::check_lines(const std::vector<std::string>& lines,
                                                      std::size_t first_index) const {
  return check_program_lines(lines, first_index);
}

ModbusBlockLink::ModbusBlockLink(ModbusBlockSettings settings, std::unique_ptr<RegisterBus> bus)
    : impl_(std::make_unique<Impl>(std::move(settings), std::move(bus))) {}

ModbusBlockLink::~ModbusBlockLink() {
  {
    std::lock_guard lock(impl_->mutex);  // so the thread cannot miss the wake-up
    impl_->shutting_down = true;
    impl_->stop_requested = true;  // a job in progress ends at its next check
  }
  impl_->wake.notify_all();
  impl_->thread.join();
}

void ModbusBlockLink::start(LineSpan span, LinkCallbacks callbacks) {
  std::unique_lock lock(impl_->mutex);
  if (impl_->running) {  // one job at a time; the running one is not disturbed
    lock.unlock();
    if (callbacks.on_done)
      callbacks.on_done(LinkOutcome{false, LinkError{LinkErrorCode::bad_request, "a job is already streaming"}, 0});
    return;
  }
  impl_->running = true;
  impl_->outcome.reset();
  impl_->callbacks = std::move(callbacks);
  impl_->progress = LinkProgress{};
  impl_->progress.lines_total = span.lines.size();
  impl_->job_start = Clock::now();
  impl_->pending_job = std::move(span);
  lock.unlock();
  impl_->wake.notify_all();
}

void ModbusBlockLink::request(RealtimeCommand command) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->realtime.push_back(command);
  }
  impl_->wake.notify_all();
}

void ModbusBlockLink::stop(LinkError why) {
  {
    std::lock_guard lock(impl_->mutex);
    if (!impl_->running) return;
    impl_->stop_reason = std::move(why);
    impl_->stop_requested = true;
  }
  impl_->wake.notify_all();
}

LinkProgress ModbusBlockLink::progress() const {
  std::lock_guard lock(impl_->mutex);
  LinkProgress p = impl_->progress;
  if (impl_->running) p.seconds = std::chrono::duration<double>(Clock::now() - impl_->job_start).count();
  return p;
}

std::optional<LinkError> ModbusBlockLink::recover(double timeout_s) {
  // The PLC's reset button clears the CNC's queue and alarm; wait for a report that says so.
  const std::size_t before = progress().statuses_received;
  request(RealtimeCommand::reset);
  const auto deadline = Clock::now() + seconds(timeout_s);
  while (Clock::now() < deadline) {
    const LinkProgress p = progress();
    if (p.statuses_received > before + 1 && p.last_status && p.last_status->state != ControllerState::alarm)
      return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return LinkError{LinkErrorCode::timeout, "the CNC is still in alarm after the PLC's reset"};
}

std::optional<LinkOutcome> ModbusBlockLink::wait(double timeout_s) {
  std::unique_lock lock(impl_->mutex);
  if (!impl_->wake.wait_for(lock, seconds(timeout_s), [&] { return !impl_->running && impl_->outcome; }))
    return std::nullopt;
  return impl_->outcome;
}

}  // namespace lamina::drivers
