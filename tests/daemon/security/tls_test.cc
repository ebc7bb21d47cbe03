// TLS on brdfd's gRPC server ([server.tls]): certificates are made at test time with the openssl
// CLI (Debian package "openssl") in a temporary directory: a test CA, a server certificate for
// 127.0.0.1 signed by it, a client certificate signed by it, and a second ("rogue") CA with a
// client certificate of its own. brdfd runs as a process without devices; the clients are the
// generated stubs over TLS channels and brdfctl with --tls/--ca/--cert/--key.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "tests/support/daemon/test_rig.h"
#include "tests/support/process_launcher.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using grpc::StatusCode;

// Runs a program (no shell) with stdout and stderr appended to `log`; its exit code, 127 when it
// could not be run, -1 when it did not finish within `timeout` (it is then killed).
int RunProgram(const std::vector<std::string>& argv, const std::string& log,
               std::chrono::milliseconds timeout = 30s) {
  LaunchOptions options(std::vector<std::string>(argv.begin() + 1, argv.end()));
  options.stderr_to = LaunchOptions::Stderr::kAppendToFile;
  options.stderr_path = log;
  options.stdout_with_stderr = true;
  options.search_path = true;
  Result<CommandResult> run = RunToCompletion(argv[0], argv[0], options, timeout);
  if (run.ok()) return run->exit_code;
  return run.status().code() == brdf::StatusCode::kTimeout ? -1 : 127;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The certificates of one test, as PEM files in `dir`.
struct Pki {
  std::string ca_cert;
  std::string server_cert, server_key;
  std::string client_cert, client_key;
  std::string rogue_ca_cert;
  std::string rogue_client_cert, rogue_client_key;
};

// P-256 keys (fast to make); the CA has keyCertSign, the server certificate is for 127.0.0.1 and
// localhost (serverAuth), the client certificates have clientAuth.
Result<Pki> MakePki(const TempDir& dir) {
  const std::string log = dir.file("openssl.log").string();
  const std::string cnf = dir.file("openssl.cnf").string();
  {
    std::ofstream out(cnf);
    out << "[req]\ndistinguished_name = dn\nprompt = no\n[dn]\nCN = brdfd test\n"
        << "[ca_ext]\nbasicConstraints = critical,CA:TRUE\n"
        << "keyUsage = critical,keyCertSign,cRLSign\nsubjectKeyIdentifier = hash\n"
        << "[server_ext]\nbasicConstraints = CA:FALSE\nkeyUsage = critical,digitalSignature\n"
        << "extendedKeyUsage = serverAuth\nsubjectAltName = IP:127.0.0.1,DNS:localhost\n"
        << "[client_ext]\nbasicConstraints = CA:FALSE\nkeyUsage = critical,digitalSignature\n"
        << "extendedKeyUsage = clientAuth\n";
    if (!out) return IoError("cannot write " + cnf);
  }
  auto path = [&dir](const std::string& name) { return dir.file(name).string(); };
  auto run = [&](const std::vector<std::string>& argv) -> Status {
    if (RunProgram(argv, log) != 0) {
      return Internal("openssl " + argv[1] + " failed; its output:\n" + ReadFile(log));
    }
    return Status::Ok();
  };
  const std::vector<std::string> ec_key = {"-newkey", "ec", "-pkeyopt",
                                           "ec_paramgen_curve:prime256v1", "-nodes"};
  auto make_ca = [&](const std::string& name, const std::string& cn) -> Status {
    std::vector<std::string> argv = {"openssl", "req",         "-x509", "-config",
                                     cnf,       "-extensions", "ca_ext"};
    argv.insert(argv.end(), ec_key.begin(), ec_key.end());
    argv.insert(argv.end(), {"-keyout", path(name + ".key"), "-out", path(name + ".crt"), "-days",
                             "2", "-subj", "/CN=" + cn});
    return run(argv);
  };
  auto make_leaf = [&](const std::string& name, const std::string& ca, const std::string& ext,
                       const std::string& serial) -> Status {
    std::vector<std::string> argv = {"openssl", "req", "-new", "-config", cnf};
    argv.insert(argv.end(), ec_key.begin(), ec_key.end());
    argv.insert(argv.end(), {"-keyout", path(name + ".key"), "-out", path(name + ".csr"), "-subj",
                             "/CN=" + name});
    BRDF_RETURN_IF_ERROR(run(argv));
    return run({"openssl", "x509", "-req", "-in", path(name + ".csr"), "-CA", path(ca + ".crt"),
                "-CAkey", path(ca + ".key"), "-set_serial", serial, "-days", "2", "-out",
                path(name + ".crt"), "-extfile", cnf, "-extensions", ext});
  };
  BRDF_RETURN_IF_ERROR(make_ca("ca", "brdfd test CA"));
  BRDF_RETURN_IF_ERROR(make_ca("rogue-ca", "someone else's CA"));
  BRDF_RETURN_IF_ERROR(make_leaf("server", "ca", "server_ext", "2"));
  BRDF_RETURN_IF_ERROR(make_leaf("client", "ca", "client_ext", "3"));
  BRDF_RETURN_IF_ERROR(make_leaf("rogue-client", "rogue-ca", "client_ext", "4"));
  return Pki{path("ca.crt"),           path("server.crt"),      path("server.key"),
             path("client.crt"),       path("client.key"),      path("rogue-ca.crt"),
             path("rogue-client.crt"), path("rogue-client.key")};
}

bool HaveOpenssl(const std::string& log) {
  return RunProgram({"openssl", "version"}, log) == 0;
}

// A daemon without devices (no such serial port, nothing on the Modbus port).
std::string TlsToml(const std::string& database, int dead_port, const std::string& listen,
                    const std::string& tls_section) {
  std::ostringstream t;
  t << "[server]\nlisten = \"" << listen << "\"\n"
    << tls_section << "[storage]\ndatabase = \"" << database << "\"\n"
    << "[meter]\nport = \"/dev/brdfd-test-no-such-port\"\n"
    << "[stage]\naddress = \"127.0.0.1:" << dead_port << "\"\nresponse_timeout_ms = 100\n"
    << "[[auth.tokens]]\nname = \"" << kOperatorName << "\"\ntoken = \"" << kOperatorToken
    << "\"\nrole = \"operator\"\n"
    << "[[auth.tokens]]\nname = \"test-analyst\"\ntoken = \"" << kAnalystToken
    << "\"\nrole = \"analyst\"\n";
  return t.str();
}

std::string TlsSection(const Pki& pki, bool client_ca) {
  std::ostringstream t;
  t << "[server.tls]\ncert = \"" << pki.server_cert << "\"\nkey = \"" << pki.server_key << "\"\n";
  if (client_ca) t << "client_ca = \"" << pki.ca_cert << "\"\n";
  return t.str();
}

// GetRigStatus over a channel with these credentials: the call's status.
grpc::Status RigStatusOver(const std::string& address,
                           const std::shared_ptr<grpc::ChannelCredentials>& credentials,
                           const std::string& token = kAnalystToken) {
  std::shared_ptr<grpc::Channel> channel = grpc::CreateChannel(address, credentials);
  std::unique_ptr<v1::Control::Stub> stub = v1::Control::NewStub(channel);
  v1::RigStatus status;
  return stub->GetRigStatus(DaemonRig::Context(token, 15s).get(), {}, &status);
}

std::shared_ptr<grpc::ChannelCredentials> Tls(const std::string& ca, const std::string& cert = "",
                                              const std::string& key = "") {
  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = ReadFile(ca);
  if (!cert.empty()) {
    ssl.pem_cert_chain = ReadFile(cert);
    ssl.pem_private_key = ReadFile(key);
  }
  return grpc::SslCredentials(ssl);
}

std::string BrdfctlBinary() {
  const char* build = std::getenv("BRDF_BUILD_DIR");
  return std::string(build ? build : BRDF_TEST_BUILD_DIR) + "/tools/brdfctl/brdfctl";
}

class TlsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!HaveOpenssl(rig_.dir().file("openssl.log").string())) {
      GTEST_SKIP() << "the openssl CLI is not installed (Debian package \"openssl\"); the TLS "
                      "tests make their certificates with it";
    }
    Result<Pki> pki = MakePki(rig_.dir());
    ASSERT_TRUE(pki.ok()) << pki.status().ToString();
    pki_ = *pki;
    Result<int> port = FreeTcpPort();
    ASSERT_TRUE(port.ok());
    dead_port_ = *port;
  }
  void TearDown() override {
    if (rig_.daemon() != nullptr) {
      Result<int> code = rig_.StopDaemon();
      EXPECT_TRUE(code.ok() && *code == 0)
          << (code.ok() ? "exit code " + std::to_string(*code) : code.status().ToString());
    }
    if (HasFailure()) std::cerr << "---- brdfd log ----\n" << rig_.log() << "\n----\n";
  }

  // Starts brdfd with [server.tls]; the address to dial ("127.0.0.1:<port>", which the server
  // certificate names, whatever address it listens on).
  std::string StartTlsDaemon(bool client_ca, const std::string& listen = "127.0.0.1:0") {
    Status st =
        rig_.StartDaemon(TlsToml(rig_.database(), dead_port_, listen, TlsSection(pki_, client_ca)));
    EXPECT_TRUE(st.ok()) << st.ToString();
    if (!st.ok()) return "";
    const std::string& address = rig_.daemon()->address();
    return "127.0.0.1:" + address.substr(address.rfind(':') + 1);
  }

  // brdfctl <flags> rig: its exit code (its output goes to brdfctl.log).
  int Brdfctl(const std::string& address, const std::vector<std::string>& flags) {
    std::vector<std::string> argv = {BrdfctlBinary(), "--address", address, "--token",
                                     kAnalystToken,   "--timeout", "15"};
    argv.insert(argv.end(), flags.begin(), flags.end());
    argv.push_back("rig");
    return RunProgram(argv, rig_.dir().file("brdfctl.log").string(), 60s);
  }

  DaemonRig rig_;
  Pki pki_;
  int dead_port_ = 0;
};

TEST_F(TlsTest, ServesTlsClientsThatTrustItsCaAndRefusesPlaintextAndStrangers) {
  // Listening on every interface with TLS: no plaintext warning.
  const std::string address = StartTlsDaemon(/*client_ca=*/false, "0.0.0.0:0");
  ASSERT_FALSE(address.empty());
  EXPECT_NE(rig_.log().find("TLS"), std::string::npos) << rig_.log();
  EXPECT_EQ(rig_.log().find("PLAINTEXT"), std::string::npos) << rig_.log();

  grpc::Status st = RigStatusOver(address, Tls(pki_.ca_cert));
  EXPECT_TRUE(st.ok()) << st.error_code() << " " << st.error_message();
  // TLS does not replace the token.
  st = RigStatusOver(address, Tls(pki_.ca_cert), "");
  EXPECT_EQ(st.error_code(), StatusCode::UNAUTHENTICATED) << st.error_message();
  // A plaintext client gets no answer at all.
  st = RigStatusOver(address, grpc::InsecureChannelCredentials());
  EXPECT_EQ(st.error_code(), StatusCode::UNAVAILABLE) << st.error_message();
  // A client that trusts another CA refuses the server.
  st = RigStatusOver(address, Tls(pki_.rogue_ca_cert));
  EXPECT_EQ(st.error_code(), StatusCode::UNAVAILABLE) << st.error_message();

  // brdfctl: --tls --ca works; plaintext does not; --ca without --tls is a usage error.
  EXPECT_EQ(Brdfctl(address, {"--tls", "--ca", pki_.ca_cert}), 0)
      << ReadFile(rig_.dir().file("brdfctl.log").string());
  EXPECT_NE(Brdfctl(address, {}), 0);
  EXPECT_NE(Brdfctl(address, {"--ca", pki_.ca_cert}), 0);
}

TEST_F(TlsTest, WithClientCaOnlyClientsWithACertificateItSignedAreServed) {
  const std::string address = StartTlsDaemon(/*client_ca=*/true);
  ASSERT_FALSE(address.empty());
  EXPECT_NE(rig_.log().find("client certificates required"), std::string::npos) << rig_.log();

  grpc::Status st = RigStatusOver(address, Tls(pki_.ca_cert, pki_.client_cert, pki_.client_key));
  EXPECT_TRUE(st.ok()) << st.error_code() << " " << st.error_message();
  // No client certificate.
  st = RigStatusOver(address, Tls(pki_.ca_cert));
  EXPECT_EQ(st.error_code(), StatusCode::UNAVAILABLE) << st.error_message();
  // A client certificate signed by another CA.
  st = RigStatusOver(address, Tls(pki_.ca_cert, pki_.rogue_client_cert, pki_.rogue_client_key));
  EXPECT_EQ(st.error_code(), StatusCode::UNAVAILABLE) << st.error_message();
  // Plaintext.
  st = RigStatusOver(address, grpc::InsecureChannelCredentials());
  EXPECT_EQ(st.error_code(), StatusCode::UNAVAILABLE) << st.error_message();

  EXPECT_EQ(Brdfctl(address, {"--tls", "--ca", pki_.ca_cert, "--cert", pki_.client_cert, "--key",
                              pki_.client_key}),
            0)
      << ReadFile(rig_.dir().file("brdfctl.log").string());
  EXPECT_NE(Brdfctl(address, {"--tls", "--ca", pki_.ca_cert}), 0);
  EXPECT_NE(Brdfctl(address, {"--tls", "--ca", pki_.ca_cert, "--cert", pki_.rogue_client_cert,
                              "--key", pki_.rogue_client_key}),
            0);
}

TEST_F(TlsTest, UnreadableOrNonPemFilesStopStartUpNamingTheKey) {
  const std::string garbage = rig_.dir().file("garbage.pem").string();
  {
    std::ofstream out(garbage);
    out << "this is not a certificate\n";
  }
  struct Case {
    std::string section;
    std::string mention;
  };
  const std::vector<Case> cases = {
      {"[server.tls]\ncert = \"" + rig_.dir().file("missing.crt").string() + "\"\nkey = \"" +
           pki_.server_key + "\"\n",
       "server.tls.cert"},
      {"[server.tls]\ncert = \"" + garbage + "\"\nkey = \"" + pki_.server_key + "\"\n",
       "server.tls.cert"},
      {"[server.tls]\ncert = \"" + pki_.server_cert + "\"\nkey = \"" + garbage + "\"\n",
       "server.tls.key"},
      {"[server.tls]\ncert = \"" + pki_.server_cert + "\"\nkey = \"" + pki_.server_key +
           "\"\nclient_ca = \"" + garbage + "\"\n",
       "server.tls.client_ca"},
      {"[server.tls]\ncert = \"" + pki_.server_cert + "\"\n", "server.tls.key"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const std::string config = rig_.dir().file("bad-tls.toml").string();
    {
      std::ofstream out(config);
      out << TlsToml(rig_.database(), dead_port_, "127.0.0.1:0", c.section);
    }
    Result<DaemonRun> run = RunBrdfd({"--config", config},
                                     rig_.dir().file("bad" + std::to_string(i) + ".log").string());
    ASSERT_TRUE(run.ok()) << run.status().ToString();
    EXPECT_NE(run->exit_code, 0) << c.section;
    EXPECT_NE(run->err.find(c.mention), std::string::npos) << c.section << "\n" << run->err;
  }
}

}  // namespace
}  // namespace brdf::testing
