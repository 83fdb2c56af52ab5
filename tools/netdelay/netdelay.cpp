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

[[noreturn]] void usage(const char* why) {
  if (why != nullptr) std::fprintf(stderr, "auv_netdelay: %s\n", why);
  std::fprintf(stderr,
               "usage: auv_netdelay --queue N [--delay 5ms] [--jitter 5ms] [--loss 10%%]\n"
               "                    [--seed 1] [--max-queued 4096]\n"
               "Holds each packet of NFQUEUE queue N for a delay uniform in [delay - jitter,\n"
               "delay + jitter] (>= 0), or drops it with probability loss. Inside a private\n"
               "network namespace only (see scripts/netem.sh).\n");
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  DelayOptions options;
  long queue_num = -1;
  unsigned max_queued = 4096;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "-h" || arg == "--help") usage(nullptr);
      if (i + 1 >= argc) usage(("missing value after " + arg).c_str());
      const std::string value = argv[++i];
      if (arg == "--queue")
        queue_num = std::stol(value);
      else if (arg == "--delay")
        options.delay_ms = parse_ms(value);
      else if (arg == "--jitter")
        options.jitter_ms = parse_ms(value);
      else if (arg == "--loss")
        options.loss = parse_fraction(value);
      else if (arg == "--seed")
        options.seed = std::stoull(value);
      else if (arg == "--max-queued")
        max_queued = static_cast<unsigned>(std::stoul(value));
      else
        usage(("unknown option " + arg).c_str());
    }
  } catch (const std::exception& e) {
    usage(e.what());
  }
  if (queue_num < 0 || queue_num > 65535) usage("--queue N (0..65535) is required");

  nfq_handle* handle = nfq_open();
  if (handle == nullptr) {
    std::fprintf(stderr, "auv_netdelay: nfq_open: %s\n", std::strerror(errno));
    return 1;
  }
  DelaySchedule schedule(options);
  Context ctx;
  ctx.schedule = &schedule;
  nfq_bind_pf(handle, AF_INET);  // needed by kernels before 3.8 only; harmless after
  ctx.queue = nfq_create_queue(handle, static_cast<std::uint16_t>(queue_num), &on_packet, &ctx);
  if (ctx.queue == nullptr) {
    std::fprintf(stderr, "auv_netdelay: cannot bind queue %ld: %s (another holder? root?)\n",
                 queue_num, std::strerror(errno));
    nfq_close(handle);
    return 1;
  }
  // Metadata only (the verdict needs the id, not the payload); a bounded kernel queue that
  // accepts rather than drops when full (fail-open).
  if (nfq_set_mode(ctx.queue, NFQNL_COPY_META, 0) < 0 ||
      nfq_set_queue_maxlen(ctx.queue, max_queued) < 0) {
    std::fprintf(stderr, "auv_netdelay: queue setup failed: %s\n", std::strerror(errno));
    return 1;
  }
  if (nfq_set_queue_flags(ctx.queue, NFQA_CFG_F_FAIL_OPEN, NFQA_CFG_F_FAIL_OPEN) < 0) {
    std::fprintf(stderr, "auv_netdelay: warning: no fail-open in this kernel\n");
  }
  nfnl_rcvbufsiz(nfq_nfnlh(handle), 4u << 20);
  const int fd = nfq_fd(handle);
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);

  // SIGTERM/SIGINT blocked except while waiting in ppoll: no stop request is missed.
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

  std::fprintf(stderr,
               "auv_netdelay: queue %ld bound: delay %.3f ms, jitter %.3f ms (uniform), "
               "loss %.2f %%, seed %llu, max queued %u\n",
               queue_num, options.delay_ms, options.jitter_ms, 100.0 * options.loss,
               static_cast<unsigned long long>(options.seed), max_queued);

  std::vector<char> buffer(1 << 16);
  std::vector<std::uint32_t> due;
  std::uint64_t overruns = 0;
  while (!g_stop) {
    timespec timeout{};
    timespec* timeout_ptr = nullptr;
    if (const auto next = schedule.next_due()) {
      const auto wait = std::max(*next - Clock::now(), Clock::duration::zero());
      const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
      timeout.tv_sec = static_cast<time_t>(ns / 1000000000);
      timeout.tv_nsec = static_cast<long>(ns % 1000000000);
      timeout_ptr = &timeout;
    }
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ppoll(&pfd, 1, timeout_ptr, &wait_mask);
    if (ready < 0 && errno != EINTR) {
      std::fprintf(stderr, "auv_netdelay: ppoll: %s\n", std::strerror(errno));
      break;
    }
    if (ready > 0) {
      for (;;) {
        const ssize_t n = recv(fd, buffer.data(), buffer.size(), 0);
        if (n < 0) {
          if (errno == ENOBUFS) {  // the kernel dropped messages to us: fail-open covers them
            ++overruns;
            continue;
          }
          break;  // EAGAIN: drained
        }
        nfq_handle_packet(handle, buffer.data(), static_cast<int>(n));
      }
    }
    due.clear();
    schedule.release_due(Clock::now(), due);
    accept_all(ctx, due);
  }
  due.clear();
  schedule.release_all(due);
  accept_all(ctx, due);
  const DelayStats& s = schedule.stats();
  const std::uint64_t delayed = s.packets - s.dropped;
  std::fprintf(stderr,
               "auv_netdelay: %llu packets: %llu delayed (mean %.3f ms), %llu dropped (%.2f %%), "
               "max held %zu, socket overruns %llu, verdict errors %llu\n",
               static_cast<unsigned long long>(s.packets), static_cast<unsigned long long>(delayed),
               delayed ? s.delay_sum_ms / delayed : 0.0, static_cast<unsigned long long>(s.dropped),
               s.packets ? 100.0 * s.dropped / s.packets : 0.0, s.max_pending,
               static_cast<unsigned long long>(overruns),
               static_cast<unsigned long long>(ctx.verdict_errors));
  nfq_destroy_queue(ctx.queue);
  nfq_close(handle);
  return 0;
}
