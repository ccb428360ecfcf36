#include "viewline/robots/ptu_link.h"

#include <arpa/inet.h>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <array>

namespace viewline::robots {

namespace {

using Clock = std::chrono::steady_clock;

int msUntil(PtuLink::Deadline deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  // Round a sub-millisecond remainder up: poll(0) would spin without ever waiting.
  return left <= 0 ? 0 : static_cast<int>(std::min<long long>(left + 1, 60'000));
}

[[noreturn]] void throwErrno(int err, const std::string& port, const std::string& action) {
  PtuLinkErrorKind kind = PtuLinkErrorKind::Io;
  std::string why = std::strerror(err);
  switch (err) {
    case ENOENT:
    case ENODEV:
    case ENXIO:
      kind = PtuLinkErrorKind::Missing;
      why = "no such device (is the unit plugged in and the path right?)";
      break;
    case ECONNREFUSED:
    case EHOSTUNREACH:
    case ENETUNREACH:
      kind = PtuLinkErrorKind::Missing;
      why = "nothing answers at this address (" + why + ")";
      break;
    case EACCES:
    case EPERM:
      kind = PtuLinkErrorKind::Permission;
      why = "permission denied (add the user to group dialout, or check the device's mode)";
      break;
    case EBUSY:
    case EWOULDBLOCK:
      kind = PtuLinkErrorKind::Busy;
      why = "device busy (another program has it open)";
      break;
    case EIO:
    case EPIPE:
    case ECONNRESET:
      kind = PtuLinkErrorKind::Disconnected;
      why = "link lost (" + why + ")";
      break;
    case ETIMEDOUT:
      kind = PtuLinkErrorKind::Timeout;
      break;
    default:
      break;
  }
  throw PtuLinkError(kind, port, "PTU link " + port + ": " + action + ": " + why);
}

// Appends what is readable now (or waits until `deadline` for the first bytes) to `buffer`.
// Returns false on time-out; throws on disconnect or error.
bool fill(int fd, std::string& buffer, const std::string& port, PtuLink::Deadline deadline) {
  pollfd p{fd, POLLIN, 0};
  const int ready = ::poll(&p, 1, msUntil(deadline));
  if (ready < 0) {
    if (errno == EINTR) return true;  // the caller re-checks its deadline
    throwErrno(errno, port, "poll");
  }
  if (ready == 0) return false;
  std::array<char, 512> chunk{};
  const ssize_t n = ::read(fd, chunk.data(), chunk.size());
  if (n > 0) {
    buffer.append(chunk.data(), static_cast<std::size_t>(n));
    return true;
  }
  if (n == 0) {
    throw PtuLinkError(PtuLinkErrorKind::Disconnected, port, "PTU link " + port + ": the other end closed the link");
  }
  if (errno == EAGAIN || errno == EINTR) return true;
  throwErrno(errno, port, "read");
}

std::string readLineFd(int fd, std::string& buffer, const std::string& port, PtuLink::Deadline deadline) {
  for (;;) {
    const std::size_t nl = buffer.find('\n');
    if (nl != std::string::npos) {
      std::string line = buffer.substr(0, nl);
      buffer.erase(0, nl + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return line;
    }
    // A peer streaming bytes without an end of line must not hold the caller past its deadline.
    if (buffer.size() > 4096) {
      buffer.clear();
      throw PtuLinkError(PtuLinkErrorKind::Io, port, "PTU link " + port + ": over 4096 bytes without an end of line (wrong baud rate?)");
    }
    if (Clock::now() >= deadline || !fill(fd, buffer, port, deadline)) {
      throw PtuLinkError(PtuLinkErrorKind::Timeout, port,
                         "PTU link " + port + ": time-out waiting for a reply line" +
                             (buffer.empty() ? std::string(" (nothing received)")
                                             : " (received " + std::to_string(buffer.size()) + " bytes without end of line)"));
    }
  }
}

void writeFd(int fd, std::string_view bytes, const std::string& port, PtuLink::Deadline deadline, bool socket) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    pollfd p{fd, POLLOUT, 0};
    const int ready = ::poll(&p, 1, msUntil(deadline));
    if (ready < 0 && errno != EINTR) throwErrno(errno, port, "poll");
    if (ready == 0) throw PtuLinkError(PtuLinkErrorKind::Timeout, port, "PTU link " + port + ": time-out writing a command");
    if (ready < 0) continue;
    if (p.revents & (POLLHUP | POLLERR)) {
      throw PtuLinkError(PtuLinkErrorKind::Disconnected, port, "PTU link " + port + ": the other end closed the link");
    }
    // MSG_NOSIGNAL: a peer that went away gives EPIPE here instead of killing the process.
    const ssize_t n = socket ? ::send(fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL)
                             : ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      throwErrno(errno, port, "write");
    }
    done += static_cast<std::size_t>(n);
  }
}

void drainFd(int fd, std::string& buffer, const std::string& port) {
  buffer.clear();
  std::array<char, 512> chunk{};
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 0) <= 0) return;
    const ssize_t n = ::read(fd, chunk.data(), chunk.size());
    if (n == 0) throw PtuLinkError(PtuLinkErrorKind::Disconnected, port, "PTU link " + port + ": the other end closed the link");
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) return;
      throwErrno(errno, port, "read");
    }
  }
}

speed_t baudConstant(int baud, const std::string& port) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    default:
      throw PtuLinkError(PtuLinkErrorKind::BadAddress, port,
                         "PTU link " + port + ": baud rate " + std::to_string(baud) +
                             " is not supported (9600, 19200, 38400, 57600 or 115200)");
  }
}

}  // namespace

PtuLinkError::PtuLinkError(PtuLinkErrorKind kind, std::string port, const std::string& what)
    : core::Error(what), kind_(kind), port_(std::move(port)) {}

const char* toString(PtuLinkErrorKind kind) {
  switch (kind) {
    case PtuLinkErrorKind::Missing: return "missing";
    case PtuLinkErrorKind::Busy: return "busy";
    case PtuLinkErrorKind::Permission: return "permission";
    case PtuLinkErrorKind::Timeout: return "time-out";
    case PtuLinkErrorKind::Disconnected: return "disconnected";
    case PtuLinkErrorKind::Io: return "i/o";
    case PtuLinkErrorKind::BadAddress: return "bad address";
  }
  return "?";
}

PtuLink::Deadline deadlineIn(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// --- serial ---------------------------------------------------------------------------------

SerialPtuLink::SerialPtuLink(const std::string& device, int baud) : port_(device) {
  const speed_t speed = baudConstant(baud, device);
  fd_ = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throwErrno(errno, device, "open");
  try {
    // Advisory lock (what other well-behaved programs check) and TIOCEXCL (refuses further
    // opens by non-root processes): a second driver on the same unit would interleave replies.
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) throwErrno(errno == EWOULDBLOCK ? EBUSY : errno, device, "lock");
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) throwErrno(errno, device, "tcgetattr (not a serial port?)");
    ::cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS);
    tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    ::cfsetispeed(&tio, speed);
    ::cfsetospeed(&tio, speed);
    if (::tcsetattr(fd_, TCSANOW, &tio) != 0) throwErrno(errno, device, "tcsetattr");
    ::ioctl(fd_, TIOCEXCL);
    ::tcflush(fd_, TCIOFLUSH);
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

SerialPtuLink::~SerialPtuLink() {
  if (fd_ >= 0) ::close(fd_);
}

void SerialPtuLink::write(std::string_view bytes, Deadline deadline) { writeFd(fd_, bytes, port_, deadline, false); }
std::string SerialPtuLink::readLine(Deadline deadline) { return readLineFd(fd_, buffer_, port_, deadline); }
void SerialPtuLink::drain() { drainFd(fd_, buffer_, port_); }

// --- TCP ------------------------------------------------------------------------------------

std::pair<std::string, int> parseHostPort(const std::string& spec) {
  const std::size_t colon = spec.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 >= spec.size()) {
    throw PtuLinkError(PtuLinkErrorKind::BadAddress, spec, "PTU link: '" + spec + "' is not host:port (e.g. 127.0.0.1:4000)");
  }
  const std::string digits = spec.substr(colon + 1);
  if (digits.size() > 5 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    throw PtuLinkError(PtuLinkErrorKind::BadAddress, spec, "PTU link: '" + spec + "': the port must be a number 1..65535");
  }
  const int port = std::stoi(digits);
  if (port < 1 || port > 65535) {
    throw PtuLinkError(PtuLinkErrorKind::BadAddress, spec, "PTU link: '" + spec + "': the port must be a number 1..65535");
  }
  return {spec.substr(0, colon), port};
}

TcpPtuLink::TcpPtuLink(const std::string& host, int port, double connect_timeout)
    : port_(host + ":" + std::to_string(port)) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 || !found) {
    throw PtuLinkError(PtuLinkErrorKind::BadAddress, port_, "PTU link " + port_ + ": cannot resolve host '" + host + "'");
  }
  sockaddr_in addr{};
  std::memcpy(&addr, found->ai_addr, sizeof addr);
  ::freeaddrinfo(found);
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throwErrno(errno, port_, "socket");
  try {
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      if (errno != EINPROGRESS) throwErrno(errno, port_, "connect");
      pollfd p{fd_, POLLOUT, 0};
      const int ready = ::poll(&p, 1, msUntil(deadlineIn(connect_timeout)));
      if (ready == 0) throw PtuLinkError(PtuLinkErrorKind::Timeout, port_, "PTU link " + port_ + ": connect: time-out");
      int err = 0;
      socklen_t len = sizeof err;
      ::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &err, &len);
      if (ready < 0) err = errno;
      if (err != 0) throwErrno(err, port_, "connect");
    }
    const int one = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

TcpPtuLink::~TcpPtuLink() {
  if (fd_ >= 0) ::close(fd_);
}

void TcpPtuLink::write(std::string_view bytes, Deadline deadline) { writeFd(fd_, bytes, port_, deadline, true); }
std::string TcpPtuLink::readLine(Deadline deadline) { return readLineFd(fd_, buffer_, port_, deadline); }
void TcpPtuLink::drain() { drainFd(fd_, buffer_, port_); }

}  // namespace viewline::robots
