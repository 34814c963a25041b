// The SocketCAN backend on a real (virtual) CAN bus.
//
// Suites named Vcan* need vcan0 and vcan1 up, as tools/vcan-bus.sh --vcan 2 provides in a guest
// kernel (the ctest entries socketcan_uml, socketcan_qemu). The others run anywhere; on a kernel
// without CAN (the host, ctest entry socketcan_host) they check the "no CAN support" error.
#include "plinth/hal/can_supervisor.h"
#include "plinth/hal/socketcan.h"

#include <fcntl.h>
#include <libsocketcan.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

#if defined(__SANITIZE_ADDRESS__)
#define PLINTH_COUNTS_HEAP_ALLOCATIONS 0  // ASan brings its own malloc
#else
#define PLINTH_COUNTS_HEAP_ALLOCATIONS 1
// Every heap allocation of the process, C and C++ (operator new calls malloc), is counted: the
// receive and send paths must make none.
namespace {
std::atomic<long> g_heap_allocations{0};
}  // namespace
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* malloc(std::size_t size) noexcept {
  g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) noexcept {
  g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(pointer, size);
}
}
#endif

namespace plinth::hal {
namespace {

using namespace std::chrono_literals;

constexpr const char* kBus = "vcan0";
constexpr const char* kSpareBus = "vcan1";  // the one tests take down and up again

can::CanFrame make_frame(std::uint32_t id, std::uint8_t length = 8, std::uint8_t first = 0x10) {
  can::CanFrame f;
  f.id = id;
  f.length = length;
  for (std::size_t i = 0; i < f.data.size(); ++i) {
    f.data[i] = static_cast<std::uint8_t>(first + i);
  }
  return f;
}

SocketCanPort open_port(const char* name, const SocketCanOptions& options = {}) {
  SocketCanOpenResult r = SocketCanPort::open(name, options);
  if (!r.ok()) throw std::runtime_error(r.message);  // fails the test with the message
  return std::move(*r.port);
}

// Any frame, as SocketCAN sees it (extended, RTR, error flag): a bare CAN_RAW socket.
bool send_raw(const char* interface_name, std::uint32_t can_id, std::uint8_t length) {
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) return false;
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(if_nametoindex(interface_name));
  can_frame frame{};
  frame.can_id = can_id;
  frame.len = length;
  const bool sent = bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0 &&
                    write(fd, &frame, sizeof(frame)) == static_cast<ssize_t>(sizeof(frame));
  close(fd);
  return sent;
}

std::int64_t realtime_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void expect_same_frame(const can::CanFrame& got, const can::CanFrame& sent) {
  EXPECT_EQ(got.id, sent.id);
  ASSERT_EQ(got.length, sent.length);
  for (std::size_t i = 0; i < sent.length; ++i) EXPECT_EQ(got.data[i], sent.data[i]) << i;
}

// A child process with its stdout in a pipe.
struct Child {
  pid_t pid = -1;
  int stdout_fd = -1;
};

std::optional<Child> spawn(const std::vector<std::string>& args) {
  int out[2];
  if (pipe(out) != 0) return std::nullopt;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, out[0]);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  Child child;
  const int e = posix_spawnp(&child.pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(out[1]);
  if (e != 0) {
    close(out[0]);
    return std::nullopt;
  }
  child.stdout_fd = out[0];
  return child;
}

std::string read_all(int fd) {
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = read(fd, buffer, sizeof(buffer))) > 0;) {
    text.append(buffer, static_cast<std::size_t>(n));
  }
  close(fd);
  return text;
}

// ---------------------------------------------------------------------------------------------
// Anywhere: no CAN needed

TEST(NoCanKernel, OpenSaysTheKernelHasNoCanAndNamesTheInterface) {
  const int probe = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (probe >= 0) {
    close(probe);
    GTEST_SKIP() << "this kernel has CAN: the no-CAN error cannot happen here";
  }
  // An interface that exists (the loopback): the kernel's lack of CAN is the reason.
  const SocketCanOpenResult r = SocketCanPort::open("lo");
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.port.has_value());
  EXPECT_EQ(r.error, OpenError::kNoCanSupport);
  EXPECT_EQ(r.error_number, EAFNOSUPPORT);
  EXPECT_NE(r.message.find("cannot open CAN interface lo: "), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("this kernel has no CAN support"), std::string::npos) << r.message;
  // A missing one is reported as missing first, the kernel's lack of CAN after it.
  const SocketCanOpenResult missing = SocketCanPort::open("vcan0");
  EXPECT_EQ(missing.error, OpenError::kNoSuchInterface);
  EXPECT_NE(missing.message.find("cannot open CAN interface vcan0: the interface does not exist"),
            std::string::npos)
      << missing.message;
  EXPECT_NE(missing.message.find("and this kernel has no CAN support"), std::string::npos)
      << missing.message;
}

TEST(Open, RefusesEmptyAndTooLongNames) {
  const SocketCanOpenResult empty = SocketCanPort::open("");
  EXPECT_EQ(empty.error, OpenError::kBadName);
  EXPECT_NE(empty.message.find("empty"), std::string::npos) << empty.message;

  const SocketCanOpenResult long_name = SocketCanPort::open("sixteen_chars_ab");
  EXPECT_EQ(long_name.error, OpenError::kBadName);
  EXPECT_NE(long_name.message.find("sixteen_chars_ab"), std::string::npos) << long_name.message;
  EXPECT_NE(long_name.message.find("at most 15"), std::string::npos) << long_name.message;
}

TEST(Filters, PlinthFilterIsExactlyThePlinthRangeOfStandardDataFrames) {
  const CanIdFilter f = kPlinthFilters[0];
  const auto passes = [&](std::uint32_t can_id) { return (can_id & f.mask) == (f.id & f.mask); };
  for (std::uint32_t id = 0; id <= kCanSffMask; ++id) {
    EXPECT_EQ(passes(id), id >= can::kFirstPlinthId && id <= can::kLastPlinthId) << id;
  }
  EXPECT_FALSE(passes(0x301 | kCanEffFlag));
  EXPECT_FALSE(passes(0x301 | kCanRtrFlag));
}

TEST(ErrorFrame, BusOff) {
  const CanBusError e = decode_error_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {});
  EXPECT_TRUE(e.has(bus_error_class::kBusOff));
  EXPECT_EQ(error_state(e), ControllerState::kBusOff);
  std::array<char, 128> text{};
  describe_bus_error(e, text);
  EXPECT_STREQ(text.data(), "bus-off");
}

TEST(ErrorFrame, ControllerWarningAndPassiveWithCounters) {
  const CanBusError warning =
      decode_error_frame(CAN_ERR_FLAG | CAN_ERR_CRTL | CAN_ERR_CNT,
                         {0, CAN_ERR_CRTL_RX_WARNING, 0, 0, 0, 0, 12, 97});
  EXPECT_EQ(error_state(warning), ControllerState::kErrorWarning);
  EXPECT_EQ(warning.tx_error_count, 12);
  EXPECT_EQ(warning.rx_error_count, 97);

  const CanBusError passive = decode_error_frame(
      CAN_ERR_FLAG | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_PASSIVE | CAN_ERR_CRTL_RX_WARNING, 0, 0, 0,
                                    0, 0, 0});
  EXPECT_EQ(error_state(passive), ControllerState::kErrorPassive);
  std::array<char, 128> text{};
  describe_bus_error(passive, text);
  EXPECT_STREQ(text.data(), "controller: rx error-warning, tx error-passive");

  const CanBusError active =
      decode_error_frame(CAN_ERR_FLAG | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_ACTIVE, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(error_state(active), ControllerState::kErrorActive);
}

TEST(ErrorFrame, ProtocolViolationLostArbitrationAndTheRest) {
  const CanBusError e = decode_error_frame(
      CAN_ERR_FLAG | CAN_ERR_PROT | CAN_ERR_LOSTARB | CAN_ERR_ACK | CAN_ERR_TX_TIMEOUT |
          CAN_ERR_TRX | CAN_ERR_BUSERROR | CAN_ERR_RESTARTED | CAN_ERR_CNT,
      {5, 0, CAN_ERR_PROT_STUFF | CAN_ERR_PROT_TX, CAN_ERR_PROT_LOC_CRC_SEQ,
       CAN_ERR_TRX_CANH_NO_WIRE, 0, 128, 3});
  EXPECT_EQ(e.arbitration_bit, 5);
  EXPECT_EQ(e.protocol_type, CAN_ERR_PROT_STUFF | CAN_ERR_PROT_TX);
  EXPECT_EQ(e.protocol_location, CAN_ERR_PROT_LOC_CRC_SEQ);
  EXPECT_EQ(e.transceiver, CAN_ERR_TRX_CANH_NO_WIRE);
  EXPECT_EQ(error_state(e), ControllerState::kErrorActive);  // no state change reported
  std::array<char, 256> text{};
  describe_bus_error(e, text);
  EXPECT_STREQ(text.data(),
               "protocol violation: stuff error, on transmission at CRC sequence; lost "
               "arbitration at bit 5; transceiver status 0x04; no ACK on transmission; transmit "
               "timeout; bus error; controller restarted; counters tx 128 rx 3");
}

TEST(ErrorFrame, DescriptionIsTruncatedToTheBufferAndTerminated) {
  const CanBusError e = decode_error_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF | CAN_ERR_CNT, {});
  std::array<char, 8> text{};
  text.fill('x');
  EXPECT_EQ(describe_bus_error(e, text), 7U);
  EXPECT_STREQ(text.data(), "bus-off");
  EXPECT_EQ(describe_bus_error(e, std::span<char>()), 0U);
}

TEST(Supervisor, LinkStateOfLoopbackAndOfAMissingInterface) {
  const Supervised<LinkState> lo = CanInterfaceSupervisor("lo").link_state();
  ASSERT_TRUE(lo.result.ok()) << lo.result.message;
  EXPECT_TRUE(lo.value.up);

  const Supervised<LinkState> missing = CanInterfaceSupervisor("vcan9").link_state();
  EXPECT_EQ(missing.result.status, SupervisionStatus::kFailed);
  EXPECT_EQ(missing.result.error_number, ENODEV);
  EXPECT_NE(missing.result.message.find("vcan9 does not exist"), std::string::npos)
      << missing.result.message;
}

// ---------------------------------------------------------------------------------------------
// On vcan0 / vcan1

TEST(Vcan, RoundTripBetweenTwoPorts) {
  SocketCanPort sender = open_port(kBus);
  SocketCanPort receiver = open_port(kBus);
  const std::array<can::CanFrame, 3> frames{make_frame(0x301, 8, 0x00), make_frame(0x320, 8, 0x40),
                                            make_frame(0x37F, 8, 0xF0)};
  for (const can::CanFrame& f : frames) ASSERT_EQ(sender.send(f), IoStatus::kOk);
  for (const can::CanFrame& f : frames) {
    TimedFrame got;
    ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kOk);
    expect_same_frame(got.frame, f);
  }
  // A port does not hear itself unless asked (the kernel's default, kept).
  TimedFrame own;
  EXPECT_EQ(sender.receive(own, 0), IoStatus::kTimeout);
}

TEST(Vcan, OwnFramesWhenAsked) {
  SocketCanOptions options;
  options.receive_own_frames = true;
  SocketCanPort port = open_port(kBus, options);
  ASSERT_EQ(port.send(make_frame(0x340)), IoStatus::kOk);
  TimedFrame got;
  ASSERT_EQ(port.receive(got, 1000), IoStatus::kOk);
  EXPECT_EQ(got.frame.id, 0x340U);
}

TEST(Vcan, MovedPortKeepsTheSocket) {
  SocketCanPort a = open_port(kBus);
  SocketCanPort receiver = open_port(kBus);
  SocketCanPort b = std::move(a);
  ASSERT_EQ(b.send(make_frame(0x302)), IoStatus::kOk);
  TimedFrame got;
  ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kOk);
  EXPECT_EQ(got.frame.id, 0x302U);
  EXPECT_EQ(a.send(make_frame(0x302)), IoStatus::kIoError);  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(a.last_error(), EBADF);
}

TEST(Vcan, DefaultFiltersPassOnlyPlinthStandardDataFrames) {
  SocketCanPort sender = open_port(kBus);
  SocketCanPort receiver = open_port(kBus);
  ASSERT_EQ(sender.send(make_frame(0x123)), IoStatus::kOk);
  ASSERT_EQ(sender.send(make_frame(0x2FF)), IoStatus::kOk);
  ASSERT_EQ(sender.send(make_frame(0x380)), IoStatus::kOk);
  ASSERT_TRUE(send_raw(kBus, 0x301 | CAN_EFF_FLAG, 8));  // extended id 0x00000301
  ASSERT_TRUE(send_raw(kBus, 0x301 | CAN_RTR_FLAG, 0));
  ASSERT_EQ(sender.send(make_frame(0x305)), IoStatus::kOk);
  TimedFrame got;
  ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kOk);
  EXPECT_EQ(got.frame.id, 0x305U);  // the first frame through is the last one sent
  EXPECT_EQ(receiver.receive(got, 0), IoStatus::kTimeout);
}

TEST(Vcan, WiderFiltersReportOtherFramesAsNotPlinth) {
  SocketCanPort sender = open_port(kBus);
  SocketCanPort receiver = open_port(kBus);
  ASSERT_EQ(receiver.set_filters(kAllFrames), 0);
  ASSERT_EQ(sender.send(make_frame(0x123)), IoStatus::kOk);
  ASSERT_TRUE(send_raw(kBus, 0x301 | CAN_EFF_FLAG, 8));
  ASSERT_TRUE(send_raw(kBus, 0x301 | CAN_RTR_FLAG, 0));
  TimedFrame got;
  got.frame.id = 0xABC;  // untouched on kNotPlinth
  ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kNotPlinth);
  EXPECT_EQ(receiver.last_rejected_can_id(), 0x123U);
  ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kNotPlinth);
  EXPECT_EQ(receiver.last_rejected_can_id(), 0x301U | CAN_EFF_FLAG);
  ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kNotPlinth);
  EXPECT_EQ(receiver.last_rejected_can_id(), 0x301U | CAN_RTR_FLAG);
  EXPECT_FALSE(receiver.last_rejected_was_fd());
  EXPECT_EQ(got.frame.id, 0xABCU);
}

TEST(Vcan, WrongLengthsOnPlinthIdsAreDeliveredForTheCodecToRefuse) {
  SocketCanPort sender = open_port(kBus);
  SocketCanPort receiver = open_port(kBus);
  for (const std::uint8_t length : {std::uint8_t{0}, std::uint8_t{3}, std::uint8_t{7}}) {
    const can::CanFrame sent = make_frame(0x301, length);
    ASSERT_EQ(sender.send(sent), IoStatus::kOk);
    TimedFrame got;
    ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kOk);
    expect_same_frame(got.frame, sent);
    can::SensorAcceleration message;
    EXPECT_EQ(can::decode(got.frame, message).error, can::CodecError::kWrongLength);
  }
}

TEST(Vcan, SendRefusesWhatIsNoClassicStandardFrame) {
  SocketCanPort port = open_port(kBus);
  EXPECT_EQ(port.send(make_frame(0x800)), IoStatus::kIoError);
  EXPECT_EQ(port.last_error(), EINVAL);
  can::CanFrame too_long = make_frame(0x301);
  too_long.length = 9;
  EXPECT_EQ(port.send(too_long), IoStatus::kIoError);
  EXPECT_EQ(port.last_error(), EINVAL);
}

TEST(Vcan, TimestampsAreMonotonicKernelRealtime) {
  SocketCanPort sender = open_port(kBus);
  SocketCanPort receiver = open_port(kBus);
  constexpr int kFrames = 20;
  const std::int64_t before = realtime_ns();
  for (int i = 0; i < kFrames; ++i) ASSERT_EQ(sender.send(make_frame(0x303)), IoStatus::kOk);
  std::int64_t previous = 0;
  for (int i = 0; i < kFrames; ++i) {
    TimedFrame got;
    ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kOk);
    EXPECT_GE(got.timestamp_ns, previous) << "frame " << i;
    previous = got.timestamp_ns;
  }
  const std::int64_t after = realtime_ns();
  // The kernel stamped them between the first send and the last read, on CLOCK_REALTIME.
  EXPECT_GE(previous, before);
  EXPECT_LE(previous, after);
  EXPECT_LT(after - before, 1'000'000'000);
}

TEST(Vcan, ReceiveTimesOutOnAQuietBusWithinTheTime) {
  SocketCanPort port = open_port(kBus);
  TimedFrame got;
  auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(port.receive(got, 0), IoStatus::kTimeout);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 50ms);

  start = std::chrono::steady_clock::now();
  EXPECT_EQ(port.receive(got, 100), IoStatus::kTimeout);
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_GE(waited, 99ms);
  EXPECT_LT(waited, 400ms);
}

// Sends `count` frames as fast as the socket takes them; returns how many it took.
int flood(SocketCanPort& sender, int count, std::uint32_t id) {
  int sent = 0;
  for (int i = 0; i < count; ++i) {
    IoStatus s = sender.send(make_frame(id, 8, static_cast<std::uint8_t>(i)));
    for (int retry = 0; s == IoStatus::kIoError && sender.transmit_queue_full() && retry < 100;
         ++retry) {
      std::this_thread::sleep_for(1ms);
      s = sender.send(make_frame(id, 8, static_cast<std::uint8_t>(i)));
    }
    if (s == IoStatus::kOk) ++sent;
  }
  return sent;
}

SocketCanOptions tiny_receive_buffer() {
  SocketCanOptions options;
  options.receive_buffer_bytes = 1;  // the kernel raises it to its minimum: a few frames
  return options;
}

TEST(Vcan, DropsAtTheEndOfABurstAreReportedBeforeTheTimeout) {
  SocketCanPort sender = open_port(kBus);
  SocketCanPort receiver = open_port(kBus, tiny_receive_buffer());
  const int sent = flood(sender, 300, 0x304);
  ASSERT_EQ(sent, 300);
  int delivered = 0;
  TimedFrame got;
  IoStatus s;
  while ((s = receiver.receive(got, 0)) == IoStatus::kOk) ++delivered;
  ASSERT_EQ(s, IoStatus::kOverflow);
  EXPECT_GT(delivered, 0);
  EXPECT_GT(receiver.dropped_frames(), 0U);
  EXPECT_EQ(delivered + static_cast<int>(receiver.dropped_frames()), sent);
  EXPECT_EQ(receiver.receive(got, 0), IoStatus::kTimeout);  // reported once
  EXPECT_EQ(receiver.total_dropped_frames(), receiver.dropped_frames());
}

TEST(Vcan, DropsBeforeAFrameAreReportedAndTheFrameIsKept) {
  SocketCanPort sender = open_port(kBus);
  SocketCanPort receiver = open_port(kBus, tiny_receive_buffer());
  const int sent = flood(sender, 300, 0x304);
  TimedFrame got;
  ASSERT_EQ(receiver.receive(got, 0), IoStatus::kOk);  // makes room for one more frame
  int delivered = 1;
  ASSERT_EQ(sender.send(make_frame(0x37E)), IoStatus::kOk);  // queued after the drops
  IoStatus s;
  while ((s = receiver.receive(got, 0)) == IoStatus::kOk) ++delivered;
  ASSERT_EQ(s, IoStatus::kOverflow);
  EXPECT_EQ(delivered + static_cast<int>(receiver.dropped_frames()), sent);
  ASSERT_EQ(receiver.receive(got, 0), IoStatus::kOk);  // the frame that told of the drops
  EXPECT_EQ(got.frame.id, 0x37EU);
  EXPECT_EQ(receiver.receive(got, 0), IoStatus::kTimeout);
}

TEST(Vcan, ReceiveAndSendDoNotAllocate) {
#if PLINTH_COUNTS_HEAP_ALLOCATIONS
  const long counter_check = g_heap_allocations.load();
  std::string counted(100, 'x');
  ASSERT_GT(g_heap_allocations.load(), counter_check) << "the counter counts nothing";

  SocketCanPort sender = open_port(kBus);
  SocketCanPort receiver = open_port(kBus, tiny_receive_buffer());
  ASSERT_TRUE(send_raw(kBus, CAN_ERR_FLAG | CAN_ERR_CRTL, CAN_ERR_DLC));
  const can::CanFrame frame = make_frame(0x306);
  TimedFrame got;
  std::array<int, 7> seen{};  // per IoStatus

  const long before = g_heap_allocations.load();
  for (int i = 0; i < 100; ++i) (void)sender.send(frame);  // more than the receiver holds
  for (IoStatus s = IoStatus::kOk; s != IoStatus::kTimeout;) {
    s = receiver.receive(got, 5);
    ++seen[static_cast<std::size_t>(s)];
  }
  const long allocations = g_heap_allocations.load() - before;

  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(seen[static_cast<std::size_t>(IoStatus::kBusError)], 1);
  EXPECT_GT(seen[static_cast<std::size_t>(IoStatus::kOk)], 0);
  EXPECT_EQ(seen[static_cast<std::size_t>(IoStatus::kOverflow)], 1);
#else
  GTEST_SKIP() << "ASan replaces malloc: the allocation count runs in plain builds";
#endif
}

TEST(Vcan, ErrorFramesOnTheBusAreBusErrors) {
  SocketCanPort receiver = open_port(kBus);
  SocketCanOptions quiet;
  quiet.error_frames = false;
  SocketCanPort not_listening = open_port(kBus, quiet);
  // vcan has no controller to raise error frames; a raw socket can still put one on the bus.
  if (!send_raw(kBus, CAN_ERR_FLAG | CAN_ERR_BUSOFF | CAN_ERR_CRTL, CAN_ERR_DLC)) {
    GTEST_SKIP() << "this kernel does not pass error frames sent on vcan: " << strerror(errno);
  }
  TimedFrame got;
  ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kBusError);
  EXPECT_EQ(error_state(receiver.last_bus_error()), ControllerState::kBusOff);
  EXPECT_EQ(not_listening.receive(got, 0), IoStatus::kTimeout);
}

TEST(Vcan, OpenNamesAMissingInterface) {
  const SocketCanOpenResult r = SocketCanPort::open("vcan9");
  EXPECT_EQ(r.error, OpenError::kNoSuchInterface);
  EXPECT_EQ(r.error_number, ENODEV);
  EXPECT_NE(r.message.find("cannot open CAN interface vcan9: the interface does not exist"),
            std::string::npos)
      << r.message;
}

TEST(Vcan, OpenRefusesANonCanInterface) {
  const SocketCanOpenResult r = SocketCanPort::open("lo");
  EXPECT_EQ(r.error, OpenError::kNotCanInterface);
  EXPECT_NE(r.message.find("lo: the interface is not CAN"), std::string::npos) << r.message;
}

TEST(Vcan, InterfaceDownIsClearWhenOpeningAndWhileOpen) {
  const CanInterfaceSupervisor supervisor(kSpareBus);
  SocketCanPort port = open_port(kSpareBus);

  const SupervisionResult stopped = supervisor.stop();
  ASSERT_TRUE(stopped.ok()) << stopped.message;
  EXPECT_FALSE(supervisor.link_state().value.up);
  TimedFrame got;
  EXPECT_EQ(port.receive(got, 1000), IoStatus::kIoError);
  EXPECT_EQ(port.last_error(), ENETDOWN);
  EXPECT_EQ(port.send(make_frame(0x301)), IoStatus::kIoError);
  EXPECT_EQ(port.last_error(), ENETDOWN);

  const SocketCanOpenResult r = SocketCanPort::open(kSpareBus);
  EXPECT_EQ(r.error, OpenError::kInterfaceDown);
  EXPECT_NE(r.message.find("vcan1: the interface is down"), std::string::npos) << r.message;

  const SupervisionResult started = supervisor.start();
  ASSERT_TRUE(started.ok()) << started.message;
  const Supervised<LinkState> link = supervisor.link_state();
  ASSERT_TRUE(link.result.ok()) << link.result.message;
  EXPECT_TRUE(link.value.up);
  EXPECT_TRUE(link.value.running);
  SocketCanPort again = open_port(kSpareBus);
  ASSERT_EQ(again.send(make_frame(0x301)), IoStatus::kOk);
  ASSERT_EQ(port.receive(got, 1000), IoStatus::kOk);  // the old socket works again too
  EXPECT_EQ(got.frame.id, 0x301U);
}

TEST(VcanSupervisor, ControllerCallsAreNotSupportedOnVcan) {
  // libsocketcan itself answers -1 on a virtual interface (it has no CAN link data)...
  int raw_state = 0;
  EXPECT_EQ(can_get_state(kBus, &raw_state), -1);

  // ...which the supervisor reports as not supported, not as a fault.
  const CanInterfaceSupervisor supervisor(kBus);
  const Supervised<std::string> kind = supervisor.link_kind();
  ASSERT_TRUE(kind.result.ok()) << kind.result.message;
  EXPECT_EQ(kind.value, "vcan");

  const Supervised<ControllerState> state = supervisor.state();
  EXPECT_EQ(state.result.status, SupervisionStatus::kNotSupported);
  EXPECT_NE(state.result.message.find("vcan0 is a vcan interface"), std::string::npos)
      << state.result.message;
  EXPECT_EQ(supervisor.restart().status, SupervisionStatus::kNotSupported);
  EXPECT_EQ(supervisor.error_counters().result.status, SupervisionStatus::kNotSupported);

  const Supervised<LinkState> link = supervisor.link_state();
  ASSERT_TRUE(link.result.ok()) << link.result.message;
  EXPECT_TRUE(link.value.up);
  EXPECT_TRUE(link.value.running);
}

TEST(VcanSupervisor, MissingInterfaceIsAFailureNotUnsupported) {
  const CanInterfaceSupervisor supervisor("vcan9");
  const Supervised<ControllerState> state = supervisor.state();
  EXPECT_EQ(state.result.status, SupervisionStatus::kFailed);
  EXPECT_NE(state.result.message.find("vcan9 does not exist"), std::string::npos)
      << state.result.message;
  EXPECT_EQ(supervisor.start().status, SupervisionStatus::kFailed);
}

// can-utils, an independent SocketCAN client, against the port.
TEST(VcanCanUtils, CandumpSeesFramesThePortSends) {
  SocketCanPort sender = open_port(kBus);
  std::optional<Child> candump = spawn({"candump", "-L", "-n", "1", "-T", "3000", "vcan0,321:7FF"});
  ASSERT_TRUE(candump) << "cannot start candump: install can-utils (tools/install-deps.sh)";
  // candump may not be listening yet: send until it has seen one frame and exited.
  int status = 0;
  pid_t done = 0;
  for (int i = 0; i < 150 && done == 0; ++i) {
    ASSERT_EQ(sender.send(make_frame(0x321, 8, 0xA0)), IoStatus::kOk);
    std::this_thread::sleep_for(20ms);
    done = waitpid(candump->pid, &status, WNOHANG);
  }
  if (done == 0) {
    kill(candump->pid, SIGKILL);
    waitpid(candump->pid, &status, 0);
    FAIL() << "candump saw no frame in 3 s";
  }
  const std::string log = read_all(candump->stdout_fd);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << log;
  EXPECT_NE(log.find("vcan0 321#A0A1A2A3A4A5A6A7"), std::string::npos) << log;
}

TEST(VcanCanUtils, ThePortReceivesWhatCansendSends) {
  SocketCanPort receiver = open_port(kBus);
  std::optional<Child> cansend = spawn({"cansend", "vcan0", "305#1122334455667788"});
  ASSERT_TRUE(cansend) << "cannot start cansend: install can-utils (tools/install-deps.sh)";
  int status = 0;
  waitpid(cansend->pid, &status, 0);
  const std::string output = read_all(cansend->stdout_fd);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  TimedFrame got;
  ASSERT_EQ(receiver.receive(got, 1000), IoStatus::kOk);
  can::CanFrame expected = make_frame(0x305);
  expected.data = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
  expect_same_frame(got.frame, expected);
}

}  // namespace
}  // namespace plinth::hal
