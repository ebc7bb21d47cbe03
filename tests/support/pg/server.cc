#include "tests/support/pg/server.h"

#include <fcntl.h>
#include <grp.h>
#include <pwd.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>
#include <vector>

#include "tests/support/test_env.h"

namespace brdf::testing {
namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

std::string RandomHex(int bytes) {
  std::random_device rd;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (int i = 0; i < bytes; ++i) {
    const unsigned v = rd() & 0xff;
    out.push_back(kHex[v >> 4]);
    out.push_back(kHex[v & 15]);
  }
  return out;
}

// Runs argv (as uid/gid when drop), output to `log`; returns the child's pid (wait=false) or its
// exit code (wait=true).
Result<int> Spawn(const std::vector<std::string>& args, const std::string& log, bool drop,
                  uid_t uid, gid_t gid, bool wait) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return IoError("fork failed");
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) ::dup2(null, 0);
    ::setpgid(0, 0);
    if (drop && (::setgroups(0, nullptr) != 0 || ::setgid(gid) != 0 || ::setuid(uid) != 0)) {
      ::_exit(126);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  if (!wait) return static_cast<int>(pid);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::string PgServer::BinDir() {
  if (const char* env = std::getenv("BRDF_PG_BIN"); env != nullptr && *env != '\0') return env;
  std::error_code ec;
  if (!fs::exists("/usr/lib/postgresql", ec)) return "";
  std::string best;
  for (const auto& entry : fs::directory_iterator("/usr/lib/postgresql", ec)) {
    const fs::path bin = entry.path() / "bin";
    if (fs::exists(bin / "initdb", ec) && fs::exists(bin / "postgres", ec) && bin.string() > best) {
      best = bin.string();
    }
  }
  return best;
}

std::string PgServer::Unavailable() {
  std::error_code ec;
  const std::string bin = BinDir();
  if (bin.empty() || !fs::exists(bin + "/initdb", ec) || !fs::exists(bin + "/postgres", ec)) {
    return "PostgreSQL server binaries not found (/usr/lib/postgresql/<version>/bin/initdb); "
           "run deploy/install-deps.sh (package postgresql-15) to run the archive tests";
  }
  return "";
}

Result<std::unique_ptr<PgServer>> PgServer::Start() {
  return Start(Options());
}

Result<std::unique_ptr<PgServer>> PgServer::Start(const Options& options) {
  std::unique_ptr<PgServer> s(new PgServer());
  s->bin_ = BinDir();
  if (s->bin_.empty()) return NotFound(Unavailable());
  // As root the server runs as `nobody`, who must be able to reach the directory: /tmp then
  // (world-searchable), not a TMPDIR that may be private to root. The unix socket's path must
  // also stay short (sun_path is 108 bytes).
  const char* tmp = std::getenv("TMPDIR");
  const bool use_tmpdir =
      ::geteuid() != 0 && tmp != nullptr && *tmp != '\0' && std::strlen(tmp) < 60;
  std::string pattern = std::string(use_tmpdir ? tmp : "/tmp") + "/brdf-pg-XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) return IoError("mkdtemp " + pattern + " failed");
  s->dir_ = pattern;
  if (options.disk_bytes > 0) {
    const std::string size = "size=" + std::to_string(options.disk_bytes) + ",mode=0700";
    if (::mount("tmpfs", s->dir_.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, size.c_str()) != 0) {
      return FailedPrecondition("mounting a " + std::to_string(options.disk_bytes >> 20) +
                                " MiB tmpfs on " + s->dir_ + " for the server's disk failed (" +
                                std::strerror(errno) + "): a full-disk test needs CAP_SYS_ADMIN");
    }
    s->tmpfs_ = true;
  }
  if (::geteuid() == 0) {
    const passwd* nobody = ::getpwnam("nobody");
    if (nobody == nullptr) return FailedPrecondition("running as root and no user `nobody`");
    s->drop_privileges_ = true;
    s->uid_ = nobody->pw_uid;
    s->gid_ = nobody->pw_gid;
    if (::chown(s->dir_.c_str(), s->uid_, s->gid_) != 0) {
      return IoError("chown " + s->dir_ + " to nobody failed");
    }
    // The directory must be reachable by nobody: its parents are /tmp-like (world-searchable).
  }
  ::chmod(s->dir_.c_str(), 0700);
  BRDF_ASSIGN_OR_RETURN(int port, FreeTcpPort());
  s->port_ = port;
  s->password_ = RandomHex(12);
  const std::string pwfile = s->dir_ + "/pwfile";
  {
    std::ofstream pw(pwfile);
    pw << s->password_ << "\n";
  }
  if (s->drop_privileges_) (void)::chown(pwfile.c_str(), s->uid_, s->gid_);
  BRDF_ASSIGN_OR_RETURN(
      int code,
      Spawn({s->bin_ + "/initdb", "-D", s->dir_ + "/data", "-U", "brdf", "--pwfile=" + pwfile,
             "--auth=scram-sha-256", "-E", "UTF8", "--locale=C", "--no-sync"},
            s->dir_ + "/initdb.log", s->drop_privileges_, s->uid_, s->gid_, true));
  if (code != 0) {
    return IoError("initdb failed (exit " + std::to_string(code) +
                   "): " + ReadFile(s->dir_ + "/initdb.log"));
  }
  BRDF_RETURN_IF_ERROR(s->Launch());
  return s;
}

Status PgServer::Launch() {
  BRDF_ASSIGN_OR_RETURN(
      int pid, Spawn({bin_ + "/postgres", "-D", dir_ + "/data", "-k", dir_, "-p",
                      std::to_string(port_), "-c", "listen_addresses=127.0.0.1", "-c", "fsync=off",
                      "-c", "full_page_writes=off", "-c", "shared_buffers=32MB", "-c",
                      "max_connections=60", "-c", "logging_collector=off"},
                     dir_ + "/postgres.log", drop_privileges_, uid_, gid_, false));
  pid_ = pid;
  return WaitReady();
}

Status PgServer::WaitReady() {
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return IoError("postgres exited while starting: " + log());
    }
    // postmaster.pid's 8th line is "ready" once the server accepts connections.
    std::ifstream pidfile(dir_ + "/data/postmaster.pid");
    std::string line;
    for (int i = 0; i < 8 && std::getline(pidfile, line); ++i) {
    }
    if (line.find("ready") != std::string::npos) return Status::Ok();
    std::this_thread::sleep_for(20ms);
  }
  return Timeout("postgres did not become ready within 30 s: " + log());
}

Status PgServer::Stop() {
  if (pid_ <= 0) return Status::Ok();
  ::kill(pid_, SIGINT);
  int status = 0;
  ::waitpid(pid_, &status, 0);
  pid_ = -1;
  return Status::Ok();
}

Status PgServer::Kill() {
  if (pid_ <= 0) return Status::Ok();
  ::kill(-pid_, SIGKILL);  // the postmaster and its backends (one process group)
  int status = 0;
  ::waitpid(pid_, &status, 0);
  pid_ = -1;
  // Orphaned backends exit once they notice; give them a moment to release shared memory.
  std::this_thread::sleep_for(200ms);
  return Status::Ok();
}

Status PgServer::Restart() {
  if (pid_ > 0) return FailedPrecondition("the server is running");
  return Launch();
}

Status PgServer::FillDisk() {
  if (!tmpfs_) return FailedPrecondition("FillDisk needs a server started with disk_bytes");
  const std::string path = dir_ + "/ballast";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
  if (fd < 0) return IoError("open " + path + ": " + std::strerror(errno));
  // Large writes first, then single pages for what is left, until the disk says ENOSPC.
  const std::vector<char> zeros(1 << 20, 0);
  for (std::size_t chunk : {zeros.size(), std::size_t{4096}}) {
    while (::write(fd, zeros.data(), chunk) > 0) {
    }
    if (errno != ENOSPC) {
      const int e = errno;
      ::close(fd);
      return IoError("writing " + path + ": " + std::strerror(e));
    }
  }
  ::close(fd);
  return Status::Ok();
}

Status PgServer::FreeDisk() {
  if (::unlink((dir_ + "/ballast").c_str()) != 0 && errno != ENOENT) {
    return IoError("removing the ballast in " + dir_ + ": " + std::strerror(errno));
  }
  return Status::Ok();
}

PgServer::~PgServer() {
  (void)Stop();
  if (tmpfs_) ::umount2(dir_.c_str(), MNT_DETACH);
  std::error_code ec;
  if (!dir_.empty()) fs::remove_all(dir_, ec);
}

std::string PgServer::conninfo() const {
  return conninfo_with_password(password_);
}

std::string PgServer::conninfo_with_password(const std::string& password) const {
  return "host=" + dir_ + " port=" + std::to_string(port_) +
         " dbname=postgres user=brdf password=" + password;
}

std::string PgServer::tcp_conninfo() const {
  return "host=127.0.0.1 port=" + std::to_string(port_) +
         " dbname=postgres user=brdf password=" + password_;
}

Result<std::string> PgServer::WriteCredentials(const std::string& path,
                                               const std::string& conninfo) {
  {
    std::ofstream out(path);
    if (!out) return IoError("cannot write " + path);
    out << "# the archive's libpq conninfo\n" << conninfo << "\n";
  }
  ::chmod(path.c_str(), 0600);
  return path;
}

Result<std::string> PgServer::Psql(const std::string& sql) const {
  std::string psql = bin_ + "/psql";
  if (!fs::exists(psql)) psql = "psql";
  const std::string sql_file = dir_ + "/query-" + RandomHex(4) + ".sql";
  {
    std::ofstream out(sql_file);
    out << sql << "\n";
  }
  const std::string command =
      "PGPASSWORD=" + password_ + " " + psql + " -X -At -v ON_ERROR_STOP=1 -h " + dir_ + " -p " +
      std::to_string(port_) + " -U brdf -d postgres -f " + sql_file + " 2>&1";
  std::FILE* p = ::popen(command.c_str(), "r");
  if (p == nullptr) return IoError("popen psql failed");
  std::string out;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  const int rc = ::pclose(p);
  std::error_code ec;
  fs::remove(sql_file, ec);
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  if (rc != 0) return IoError("psql failed: " + out);
  return out;
}

std::string PgServer::log() const {
  return ReadFile(dir_ + "/postgres.log");
}

}  // namespace brdf::testing
