// auv_netdelay: delay, jitter and loss for the packets of one NFQUEUE queue, in user space (for
// kernels without the netem qdisc). Run it inside a private network namespace (scripts/netem.sh)
// beside a rule such as
//   iptables -A OUTPUT -o lo -p udp -j NFQUEUE --queue-num 7 --queue-bypass
// Each queued packet is held for a delay drawn uniformly from [delay - jitter, delay + jitter]
// (clamped at 0) or dropped with the loss probability, then accepted. One thread: a min-heap of
// due times (DelaySchedule) and ppoll on the netlink socket with a timeout to the next due time.
// The queue is fail-open (a full queue accepts instead of dropping) and the rule's
// --queue-bypass accepts everything when no process holds the queue, so a dead tool never
// blackholes the namespace. SIGTERM/SIGINT: every held packet is accepted, the counts printed.
#include <arpa/inet.h>
#include <fcntl.h>
#include <libnetfilter_queue/libnetfilter_queue.h>
#include <linux/netfilter.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "delay_schedule.hpp"

namespace {

using namespace auvrl::netdelay;

volatile sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

/// What the packet callback needs: the schedule and counters of failed verdicts.
struct Context {
  DelaySchedule* schedule = nullptr;
  nfq_q_handle* queue = nullptr;
  std::uint64_t verdict_errors = 0;
};

int on_packet(nfq_q_handle* queue, nfgenmsg*, nfq_data* data, void* user) {
  auto* ctx = static_cast<Context*>(user);
  const nfqnl_msg_packet_hdr* header = nfq_get_msg_packet_hdr(data);
  if (header == nullptr) return 0;
  const std::uint32_t id = ntohl(header->packet_id);
  if (!ctx->schedule->admit(id, Clock::now())) {
    if (nfq_set_verdict(queue, id, NF_DROP, 0, nullptr) < 0) ++ctx->verdict_errors;
  }
  return 0;
}

void accept_all(Context& ctx, const std::vector<std::uint32_t>& ids) {
  for (std::uint32_t id : ids) {
    if (nfq_set_verdict(ctx.queue, id, NF_ACCEPT, 0, nullptr) < 0) ++ctx.verdict_errors;
  }
}

/// The command line: the impairment, the queue and its bound.
struct Args {
  DelayOptions options;
  long queue_num = -1;
  unsigned max_queued = 4096;
};

/// A --name TIME / FRACTION option parsed by the schedule's own parser (which knows the units),
/// its errors reported as CLI11's.
void add_unit_option(CLI::App& app, const std::string& name, double* target,
                     double (*parse)(const std::string&), const std::string& default_text,
                     const std::string& help) {
  app.add_option_function<std::string>(
         name,
         [name, target, parse](const std::string& text) {
           try {
             *target = parse(text);
           } catch (const std::invalid_argument& e) {
             throw CLI::ValidationError(name, e.what());
           }
         },
         help)
      ->default_str(default_text);
}

/// Parses argv with CLI11; exits with 0 after --help and 2 on a bad command line.
Args parse_args(int argc, char** argv) {
  Args a;
  CLI::App app(
      "Holds each packet of NFQUEUE queue N for a delay uniform in [delay - jitter, delay + "
      "jitter] (>= 0), or drops it with probability loss. Inside a private network namespace "
      "only (see scripts/netem.sh).",
      "auv_netdelay");
  app.add_option("--queue", a.queue_num, "NFQUEUE queue number")
      ->required()
      ->check(CLI::Range(0, 65535));
  add_unit_option(app, "--delay", &a.options.delay_ms, parse_ms, "0ms",
                  "mean delay, e.g. 5ms, 500us");
  add_unit_option(app, "--jitter", &a.options.jitter_ms, parse_ms, "0ms", "delay +- this, uniform");
  add_unit_option(app, "--loss", &a.options.loss, parse_fraction, "0%",
                  "drop probability, 10% or 0.1");
  app.add_option("--seed", a.options.seed, "seed of the draws")->capture_default_str();
  app.add_option("--max-queued", a.max_queued, "the kernel queue's bound (fail-open beyond)")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    std::exit(0);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "auv_netdelay: %s (see auv_netdelay --help)\n", e.what());
    std::exit(2);
  }
  return a;
}

/// Opens NFQUEUE, binds args.queue_num to on_packet(ctx) and sets it up (metadata only, bounded,
/// fail-open). Null (an error printed) when opening or binding fails.
nfq_handle* open_queue(const Args& args, Context& ctx) {
  nfq_handle* handle = nfq_open();
  if (handle == nullptr) {
    std::fprintf(stderr, "auv_netdelay: nfq_open: %s\n", std::strerror(errno));
    return nullptr;
  }
  nfq_bind_pf(handle, AF_INET);  // needed by kernels before 3.8 only; harmless after
  ctx.queue =
      nfq_create_queue(handle, static_cast<std::uint16_t>(args.queue_num), &on_packet, &ctx);
  if (ctx.queue == nullptr) {
    std::fprintf(stderr, "auv_netdelay: cannot bind queue %ld: %s (another holder? root?)\n",
                 args.queue_num, std::strerror(errno));
    nfq_close(handle);
    return nullptr;
  }
  // Metadata only (the verdict needs the id, not the payload); a bounded kernel queue that
  // accepts rather than drops when full (fail-open).
  if (nfq_set_mode(ctx.queue, NFQNL_COPY_META, 0) < 0 ||
      nfq_set_queue_maxlen(ctx.queue, args.max_queued) < 0) {
    std::fprintf(stderr, "auv_netdelay: queue setup failed: %s\n", std::strerror(errno));
    return nullptr;
  }
  if (nfq_set_queue_flags(ctx.queue, NFQA_CFG_F_FAIL_OPEN, NFQA_CFG_F_FAIL_OPEN) < 0) {
    std::fprintf(stderr, "auv_netdelay: warning: no fail-open in this kernel\n");
  }
  nfnl_rcvbufsiz(nfq_nfnlh(handle), 4u << 20);
  return handle;
}

/// Blocks SIGTERM/SIGINT and installs on_signal; returns the mask to wait with in ppoll (the
/// old one with both unblocked), so that no stop request is missed.
sigset_t block_stop_signals() {
  sigset_t block, wait_mask;
  sigemptyset(&block);
  sigaddset(&block, SIGTERM);
  sigaddset(&block, SIGINT);
  sigprocmask(SIG_BLOCK, &block, &wait_mask);
  sigdelset(&wait_mask, SIGTERM);
  sigdelset(&wait_mask, SIGINT);
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
  return wait_mask;
}

/// The ppoll timeout until the schedule's next due time in *storage; null when nothing is held.
timespec* timeout_to_next_due(const DelaySchedule& schedule, timespec* storage) {
  const auto next = schedule.next_due();
  if (!next) return nullptr;
  const auto wait = std::max(*next - Clock::now(), Clock::duration::zero());
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
  storage->tv_sec = static_cast<time_t>(ns / 1000000000);
  storage->tv_nsec = static_cast<long>(ns % 1000000000);
  return storage;
}

/// Hands every message waiting on the (non-blocking) socket to the library, which calls
/// on_packet; counts kernel overruns (ENOBUFS) in *overruns.
void drain_socket(nfq_handle* handle, int fd, std::vector<char>& buffer, std::uint64_t* overruns) {
  for (;;) {
    const ssize_t n = recv(fd, buffer.data(), buffer.size(), 0);
    if (n < 0) {
      if (errno == ENOBUFS) {  // the kernel dropped messages to us: fail-open covers them
        ++*overruns;
        continue;
      }
      break;  // EAGAIN: drained
    }
    nfq_handle_packet(handle, buffer.data(), static_cast<int>(n));
  }
}

/// Holds and releases packets until a stop signal (or a ppoll error), then accepts every held
/// packet. Returns the socket overruns.
std::uint64_t serve(nfq_handle* handle, Context& ctx, const sigset_t& wait_mask) {
  const int fd = nfq_fd(handle);
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
  std::vector<char> buffer(1 << 16);
  std::vector<std::uint32_t> due;
  std::uint64_t overruns = 0;
  while (!g_stop) {
    timespec timeout{};
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ppoll(&pfd, 1, timeout_to_next_due(*ctx.schedule, &timeout), &wait_mask);
    if (ready < 0 && errno != EINTR) {
      std::fprintf(stderr, "auv_netdelay: ppoll: %s\n", std::strerror(errno));
      break;
    }
    if (ready > 0) drain_socket(handle, fd, buffer, &overruns);
    due.clear();
    ctx.schedule->release_due(Clock::now(), due);
    accept_all(ctx, due);
  }
  due.clear();
  ctx.schedule->release_all(due);
  accept_all(ctx, due);
  return overruns;
}

/// The start line: the queue and the impairment.
void print_start(const Args& args) {
  const DelayOptions& options = args.options;
  std::fprintf(stderr,
               "auv_netdelay: queue %ld bound: delay %.3f ms, jitter %.3f ms (uniform), "
               "loss %.2f %%, seed %llu, max queued %u\n",
               args.queue_num, options.delay_ms, options.jitter_ms, 100.0 * options.loss,
               static_cast<unsigned long long>(options.seed), args.max_queued);
}

/// The final counts.
void print_stats(const DelayStats& s, std::uint64_t overruns, std::uint64_t verdict_errors) {
  const std::uint64_t delayed = s.packets - s.dropped;
  std::fprintf(stderr,
               "auv_netdelay: %llu packets: %llu delayed (mean %.3f ms), %llu dropped (%.2f %%), "
               "max held %zu, socket overruns %llu, verdict errors %llu\n",
               static_cast<unsigned long long>(s.packets), static_cast<unsigned long long>(delayed),
               delayed ? s.delay_sum_ms / delayed : 0.0, static_cast<unsigned long long>(s.dropped),
               s.packets ? 100.0 * s.dropped / s.packets : 0.0, s.max_pending,
               static_cast<unsigned long long>(overruns),
               static_cast<unsigned long long>(verdict_errors));
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv);
  DelaySchedule schedule(args.options);
  Context ctx;
  ctx.schedule = &schedule;
  nfq_handle* handle = open_queue(args, ctx);
  if (handle == nullptr) return 1;
  const sigset_t wait_mask = block_stop_signals();
  print_start(args);
  const std::uint64_t overruns = serve(handle, ctx, wait_mask);
  print_stats(schedule.stats(), overruns, ctx.verdict_errors);
  nfq_destroy_queue(ctx.queue);
  nfq_close(handle);
  return 0;
}
