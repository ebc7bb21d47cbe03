// The fault campaign: each row of kMatrix below is a device or storage fault injected while a
// session runs on the REAL daemon (brdfd as a process) driving the REAL drivers against brdf-sim,
// with the fault set through the simulator's control unit (unit 100) or on the daemon process
// itself (storage). The table reads as the daemon's promise about each fault:
//
//   recovers        the drivers and the executor retry it away: the session completes and is
//                   never paused;
//   pauses          the session pauses with the fault as its reason (the fault is named in the
//                   session's last fault); once the fault is cleared, Resume completes it.
//
// Every row also checks what never changes: the daemon does not exit, no reading recorded before
// the fault is lost or repeated, and at the end the database holds every planned step once with
// exactly one reading per measuring step (tests/support/daemon/test_util.h, storage's own check).
// kRtuMatrix runs the same checks with the stage on Modbus RTU (brdf-sim's RTU pty). The rows are
// listed with their promises in docs/stage-modbus.md ("The fault matrix's stage rows").
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/fs.h>
#include <netinet/in.h>
#include <sys/ioctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/daemon/rig_teardown.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/daemon/test_util.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

// Three poses after a reference and a dark (prompts: mount the white, close the shutter, mount
// the sample), so a fault can land on a reference, a dark, a sample or a move. Retries: three
// attempts, a short backoff.
const std::string kFaultPlan = PlanFixture("fault campaign")
                                   .PoseList({{0, 10, 40}, {10, 40, 40}, {20, 70, 40}})
                                   .Reference(true)
                                   .DarkWithEachReference()
                                   .Measurement(200, 1)
                                   .Retry(3, 100);

// brdfd's configuration for the campaign: the daemon tests' one WITHOUT their quality-10
// override (darks must pass on the default policy), and a meter measurement timeout that a
// silent meter uses up quickly, and a stage busy window of 1 s (exception 04/06 rows).
std::string FaultConfigToml(const SimProcess& sim, const std::string& database) {
  std::string toml = DaemonConfigToml(sim, database);
  const std::string override_10 = "[meter.quality]\n\"10\" = \"accept_and_flag\"\n";
  if (const auto at = toml.find(override_10); at != std::string::npos) {
    toml.erase(at, override_10.size());
  }
  const std::string timeout = "measurement_timeout_ms = 3000";
  if (const auto at = toml.find(timeout); at != std::string::npos) {
    toml.replace(at, timeout.size(), "measurement_timeout_ms = 1500");
  }
  const std::string stage_timeout = "response_timeout_ms = 300\n";
  if (const auto at = toml.find(stage_timeout); at != std::string::npos) {
    toml.insert(at + stage_timeout.size(), "busy_window_ms = 1000\n");
  }
  return toml;
}

// The same with the stage on Modbus RTU: brdf-sim's RTU pty (started with --rtu) instead of its
// TCP server. The test still acts on the simulator's control unit over TCP; the faults it sets
// are the same ones the RTU endpoint applies.
std::string RtuFaultConfigToml(const SimProcess& sim, const std::string& database) {
  std::string toml = FaultConfigToml(sim, database);
  const std::string tcp = "transport = \"tcp\"\naddress = \"" + sim.modbus_host() + ":" +
                          std::to_string(sim.modbus_port()) + "\"\n";
  if (const auto at = toml.find(tcp); at != std::string::npos) {
    toml.replace(at, tcp.size(),
                 "transport = \"rtu\"\ndevice = \"" + sim.rtu_path() + "\"\nbaud = 115200\n");
  }
  return toml;
}

enum class Expect { kRecovers, kPauses };

// What a row does to the rig: the simulator's control unit, or the daemon's process.
using Action = std::function<Status(DaemonRig&)>;

struct FaultCase {
  const char* name;    // the test's name
  const char* fault;   // what goes wrong, in the lab's words
  Expect expect;       // recovers or pauses (see the top of the file)
  int after_readings;  // inject once this many readings are stored (0: before submitting)
  Action inject;       //
  Action clear;        // pauses: what makes the fault go away (nothing: it was one-shot)
  const char* reason;  // pauses: a word the fault's reason must contain (case-insensitive)
  int device_code;     // pauses: the fault's device code (−1: not checked)
  // recovers: the injected fault fired (its "next N" counter ran down, its flag was consumed).
  std::function<bool(DaemonRig&)> consumed;
  // Extra checks on the readings (e.g. a flagged one), or nullptr.
  std::function<void(const std::vector<v1::Reading>&)> check_readings;
  // The meter brdf-sim simulates and brdfd drives ([meter] model); nullptr: the PR-650.
  const char* meter = nullptr;
};

// gtest prints a failing row by its name.
void PrintTo(const FaultCase& c, std::ostream* out) {
  *out << c.name;
}

// --- Actions ----------------------------------------------------------------------------------

Action Serial(std::function<void(sim::SerialFaults&)> set) {
  return [set](DaemonRig& rig) {
    sim::SerialFaults f;
    set(f);
    return rig.sim_control().SetSerialFaults(f);
  };
}
Action Modbus(std::function<void(sim::ModbusFaults&)> set) {
  return [set](DaemonRig& rig) {
    sim::ModbusFaults f;
    set(f);
    return rig.sim_control().SetModbusFaults(f);
  };
}
Status ClearSerial(DaemonRig& rig) {
  return rig.sim_control().SetSerialFaults({});
}
Status ClearModbus(DaemonRig& rig) {
  return rig.sim_control().SetModbusFaults({});
}

// Waits (bounded) until the daemon reports the meter connected again (a vanished port is back).
Status MeterBack(DaemonRig& rig) {
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < until) {
    v1::GetRigStatusRequest request;
    v1::RigStatus status;
    if (rig.control().GetRigStatus(DaemonRig::Context().get(), request, &status).ok()) {
      for (const auto& d : status.devices()) {
        if (d.name() == "meter" && d.state() == v1::CONNECTION_STATE_CONNECTED) {
          return Status::Ok();
        }
      }
    }
    std::this_thread::sleep_for(50ms);
  }
  return Timeout("the daemon did not report the meter connected within 30 s");
}

// Whether brdf-sim's Modbus TCP port accepts a connection now (the drives answer again after an
// injected outage).
bool ModbusPortAccepts(const SimProcess& sim) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(sim.modbus_port()));
  const bool parsed = inet_pton(AF_INET, sim.modbus_host().c_str(), &addr.sin_addr) == 1;
  const bool accepted =
      parsed && connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  close(fd);
  return accepted;
}

v1::ConnectionState StageState(DaemonRig& rig) {
  v1::GetRigStatusRequest request;
  v1::RigStatus status;
  if (rig.control().GetRigStatus(DaemonRig::Context().get(), request, &status).ok()) {
    for (const auto& d : status.devices()) {
      if (d.name() == "stage") return d.state();
    }
  }
  return v1::CONNECTION_STATE_UNSPECIFIED;
}

// The drives' outage is over: waits (bounded) until brdf-sim's Modbus port accepts connections
// again, then asks for rig status once, 1.8 s later: it must show the stage connected (issue 21:
// "rig status shows a device back within 2 s of it answering"). Nobody asks before, so what
// reconnected it is the daemon's own back-off (at most [stage] reconnect_max_ms, 1 s, plus one
// attempt), not the immediate retry that asking triggers (Rig::RetryStageNow).
Status StageBackWithinTwoSeconds(DaemonRig& rig) {
  const auto give_up = std::chrono::steady_clock::now() + 30s;
  while (!ModbusPortAccepts(rig.sim())) {
    if (std::chrono::steady_clock::now() >= give_up) {
      return Timeout("brdf-sim's Modbus port did not accept connections again within 30 s");
    }
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(1800ms);
  const v1::ConnectionState state = StageState(rig);
  if (state != v1::CONNECTION_STATE_CONNECTED) {
    return Timeout("the drives answer again, but 1.8 s later rig status shows the stage " +
                   v1::ConnectionState_Name(state));
  }
  return Status::Ok();
}

// Storage: a file-size limit of 0 bytes on the daemon process (prlimit): every write to the
// database and its WAL fails with EFBIG, as on a full disk or an exhausted quota. brdfd ignores
// SIGXFSZ, so the write fails instead of killing it.
Status FileSizeLimit(DaemonRig& rig, rlim_t bytes) {
  // Only the soft limit moves: raising a hard limit again would need CAP_SYS_RESOURCE.
  rlimit limit{};
  if (prlimit(rig.daemon()->pid(), RLIMIT_FSIZE, nullptr, &limit) != 0) {
    return IoError("prlimit(RLIMIT_FSIZE) of brdfd: " + std::string(std::strerror(errno)));
  }
  limit.rlim_cur = bytes == RLIM_INFINITY ? limit.rlim_max : bytes;
  if (prlimit(rig.daemon()->pid(), RLIMIT_FSIZE, &limit, nullptr) != 0) {
    return IoError("prlimit(RLIMIT_FSIZE) on brdfd failed: " + std::string(std::strerror(errno)));
  }
  return Status::Ok();
}

// Storage: the database file and its WAL made immutable (FS_IMMUTABLE_FL, what chattr +i sets):
// every write fails with EPERM even on brdfd's open descriptors, as on a filesystem remounted
// read-only. Needs CAP_LINUX_IMMUTABLE and a filesystem that has the flag (kFailedPrecondition
// when not: the row is skipped).
Status SetImmutable(const std::string& path, bool on) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return IoError("open " + path + ": " + std::strerror(errno));
  int flags = 0;
  Status st = Status::Ok();
  if (ioctl(fd, FS_IOC_GETFLAGS, &flags) != 0) {
    st = FailedPrecondition("FS_IOC_GETFLAGS on " + path + ": " + std::strerror(errno));
  } else {
    flags = on ? (flags | FS_IMMUTABLE_FL) : (flags & ~FS_IMMUTABLE_FL);
    if (ioctl(fd, FS_IOC_SETFLAGS, &flags) != 0) {
      st = FailedPrecondition("FS_IOC_SETFLAGS on " + path + ": " + std::strerror(errno));
    }
  }
  close(fd);
  return st;
}
Status DatabaseReadOnly(DaemonRig& rig, bool on) {
  BRDF_RETURN_IF_ERROR(SetImmutable(rig.database() + "-wal", on));
  return SetImmutable(rig.database(), on);
}

// --- Checks -----------------------------------------------------------------------------------

bool SerialConsumed(DaemonRig& rig) {
  Result<sim::SerialFaults> f = rig.sim_control().SerialFaults();
  return f.ok() && f->garbage_next == 0 && f->truncate_next == 0 && f->quality_count == 0 &&
         f->vanish_seconds == 0 && f->no_data_next == 0;
}
// The serial faults ran down and the meter's way out of remote mode was taken.
bool SerialAndRemoteConsumed(DaemonRig& rig) {
  Result<sim::SerialFaults> f = rig.sim_control().SerialFaults();
  return SerialConsumed(rig) && f.ok() && !f->leave_remote;
}

bool ModbusConsumed(DaemonRig& rig) {
  Result<sim::ModbusFaults> f = rig.sim_control().ModbusFaults();
  return f.ok() && f->exception_count == 0 && f->late_count == 0 && !f->drop_connection &&
         !f->alarm_mid_move && !f->stall && f->outage_ms == 0;
}

// Every reading was taken where the plan put the stage: each angle within 0.1° of a multiple of
// 10° (every pose of kFaultPlan is) and inside the travel. A feedback position read in the wrong
// word order is tens of thousands of degrees off.
void PosesOnThePlan(const std::vector<v1::Reading>& readings) {
  for (const auto& r : readings) {
    for (const double deg :
         {r.pose().alpha(), r.pose().beta(), r.pose().gamma(), r.pose().delta()}) {
      EXPECT_TRUE(std::abs(deg) <= 180.0 && std::abs(deg - 10.0 * std::round(deg / 10.0)) < 0.1)
          << "reading " << r.id()
          << " was recorded at a pose the plan never visits: " << r.pose().ShortDebugString();
    }
  }
}

std::function<void(const std::vector<v1::Reading>&)> SomeReading(int quality, bool flagged) {
  return [quality, flagged](const std::vector<v1::Reading>& readings) {
    const bool seen = std::any_of(readings.begin(), readings.end(), [&](const v1::Reading& r) {
      return r.quality_code() == quality && r.flagged() == flagged;
    });
    EXPECT_TRUE(seen) << "no reading with quality code " << quality
                      << (flagged ? " flagged" : " unflagged");
  };
}

// --- The matrix -------------------------------------------------------------------------------

const FaultCase kMatrix[] = {
    // Serial line (PR-650).
    {"SerialSilence", "the meter answers nothing (cable switch on XFER, not in remote mode)",
     Expect::kPauses, 2, Serial([](auto& f) { f.silent = true; }), ClearSerial, "PR-650", -1,
     nullptr, nullptr},
    {"SerialGarbageOnce", "one reply is garbage bytes", Expect::kRecovers, 2,
     Serial([](auto& f) { f.garbage_next = 1; }), nullptr, "", -1, SerialConsumed, nullptr},
    {"SerialGarbageKeepsComing", "every reply is garbage", Expect::kPauses, 2,
     Serial([](auto& f) { f.garbage_next = 1000; }), ClearSerial, "PR-650", -1, nullptr, nullptr},
    {"SerialTruncatedReply", "one reply stops half-way", Expect::kRecovers, 2,
     Serial([](auto& f) { f.truncate_next = 1; }), nullptr, "", -1, SerialConsumed, nullptr},
    {"SerialPortVanishesBriefly", "the port vanishes during a D5 transfer, back after 0.1 s",
     Expect::kRecovers, 2, Serial([](auto& f) { f.vanish_seconds = 5; }), nullptr, "", -1,
     SerialConsumed, nullptr},
    {"SerialPortVanishesForLong", "the port vanishes during a D5 transfer, back after 6 s",
     Expect::kPauses, 2, Serial([](auto& f) { f.vanish_seconds = 300; }), MeterBack, "vanished", -1,
     nullptr, nullptr},
    // Quality codes, one per class of the default policy (drivers/pr650/quality_codes.h).
    {"Quality18LowLightAcceptedFlagged", "quality 18 (low light): usable, flagged",
     Expect::kRecovers, 0, Serial([](auto& f) {
       f.quality_code = 18;
       f.quality_count = 1;
     }),
     nullptr, "", -1, SerialConsumed, SomeReading(18, true)},
    {"Quality19OverloadAdapted", "quality 19 (overload): integration halved, measured again",
     Expect::kRecovers, 0, Serial([](auto& f) {
       f.quality_code = 19;
       f.quality_count = 1;
     }),
     nullptr, "", -1, SerialConsumed, nullptr},
    {"Quality10WeakAdapted", "quality 10 (weak light) on a light reading: integration doubled",
     Expect::kRecovers, 0, Serial([](auto& f) {
       f.quality_code = 10;
       f.quality_count = 1;
     }),
     nullptr, "", -1, SerialConsumed, nullptr},
    {"Quality29Retried", "quality 29 (corrupted data): measured again", Expect::kRecovers, 0,
     Serial([](auto& f) {
       f.quality_code = 29;
       f.quality_count = 1;
     }),
     nullptr, "", -1, SerialConsumed, nullptr},
    {"Quality30RetriedThenFlagged", "quality 30 (noisy) on every try: accepted flagged",
     Expect::kRecovers, 0, Serial([](auto& f) {
       f.quality_code = 30;
       f.quality_count = 4;
     }),
     nullptr, "", -1, SerialConsumed, SomeReading(30, true)},
    {"Quality08SyncOffRetried", "quality 08 (sync lost): sync off, measured again",
     Expect::kRecovers, 0, Serial([](auto& f) {
       f.quality_code = 8;
       f.quality_count = 1;
     }),
     nullptr, "", -1, SerialConsumed, nullptr},
    {"Quality14Fails", "quality 14 (a failing code) on every try", Expect::kPauses, 2,
     Serial([](auto& f) {
       f.quality_code = 14;
       f.quality_count = 1000;
     }),
     ClearSerial, "quality", 14, nullptr, nullptr},
    {"QualityUnknownFails", "quality 42 (not in the reference)", Expect::kPauses, 2,
     Serial([](auto& f) {
       f.quality_code = 42;
       f.quality_count = 1000;
     }),
     ClearSerial, "quality", 42, nullptr, nullptr},
    {"SerialNoDataOnce", "one measurement gives no data: its report is \"-1\" (measured again)",
     Expect::kRecovers, 2, Serial([](auto& f) { f.no_data_next = 1; }), nullptr, "", -1,
     SerialConsumed, nullptr},
    {"SerialUncalibratedUnits", "the meter reports units code 2 (uncalibrated): flagged",
     Expect::kRecovers, 0, Serial([](auto& f) { f.units_code = 2; }), nullptr, "", -1,
     // A persistent setting, not a "next N" fault: it fired when a reading came back flagged.
     [](DaemonRig& rig) {
       Result<sim::SerialFaults> f = rig.sim_control().SerialFaults();
       return f.ok() && f->units_code == 2;
     },
     SomeReading(0, true)},
    // Modbus stage.
    {"ModbusException02", "exception 02 (illegal data address) on every axis request",
     Expect::kPauses, 2, Modbus([](auto& f) {
       f.exception_code = 2;
       f.exception_count = 1000;
     }),
     ClearModbus, "exception 2", 2, nullptr, nullptr},
    {"ModbusException06Briefly", "exception 06 (busy) on the next two requests", Expect::kRecovers,
     2, Modbus([](auto& f) {
       f.exception_code = 6;
       f.exception_count = 2;
     }),
     nullptr, "", -1, ModbusConsumed, nullptr},
    {"ModbusException06KeepsComing", "exception 06 (busy) on every request", Expect::kPauses, 2,
     Modbus([](auto& f) {
       f.exception_code = 6;
       f.exception_count = 1000;
     }),
     ClearModbus, "busy", 6, nullptr, nullptr},
    // Exception 04 (an AZ: command execution disabled) is waited out for [stage] busy_window_ms
    // (1 s here): a burst shorter than that costs nothing, a longer one pauses naming it.
    {"ModbusException04Burst", "exception 04 on the next three requests", Expect::kRecovers, 2,
     Modbus([](auto& f) {
       f.exception_code = 4;
       f.exception_count = 3;
     }),
     nullptr, "", -1, ModbusConsumed, nullptr},
    {"ModbusException04OutlastsTheBusyWindow", "exception 04 on every request", Expect::kPauses, 2,
     Modbus([](auto& f) {
       f.exception_code = 4;
       f.exception_count = 1000;
     }),
     ClearModbus, "busy_window_ms", 4, nullptr, nullptr},
    {"ModbusLateReplies", "the next two replies come after the response timeout", Expect::kRecovers,
     2, Modbus([](auto& f) {
       f.late_reply_ms = 700;
       f.late_count = 2;
     }),
     nullptr, "", -1, ModbusConsumed, nullptr},
    {"ModbusDroppedConnection", "the TCP connection drops at the next request", Expect::kRecovers,
     2, Modbus([](auto& f) { f.drop_connection = true; }), nullptr, "", -1, ModbusConsumed,
     nullptr},
    {"ModbusAlarmMidMove", "an axis raises an alarm half-way through the next move",
     Expect::kRecovers, 2, Modbus([](auto& f) { f.alarm_mid_move = true; }), nullptr, "", -1,
     ModbusConsumed, nullptr},
    {"ModbusStall", "the next move never ends (MOVE stays set)", Expect::kRecovers, 2,
     Modbus([](auto& f) { f.stall = true; }), nullptr, "", -1, ModbusConsumed, nullptr},
    // The drives' word order changed under a session (brdfd's az profile lays 32-bit values
    // upper word first): the next operation block reads as nonsense, the drive refuses it
    // (exception 03) and the session pauses saying the profile's word_order may not match the
    // drive. Nothing is recorded at a pose read in the wrong word order.
    {"StageWordOrderMismatch", "the drives switch to lower word first mid-session", Expect::kPauses,
     2, Modbus([](auto& f) { f.swap_word_order = true; }), ClearModbus, "word_order", -1, nullptr,
     PosesOnThePlan},
    {"StageWordOrderMismatchFromTheStart", "the drives are set to lower word first from the start",
     Expect::kPauses, 0, Modbus([](auto& f) { f.swap_word_order = true; }), ClearModbus,
     "word_order", -1, nullptr, PosesOnThePlan},
    // A drive that goes away (its connection closed, connections refused) and comes back: a
    // short outage is reconnected away by the bus; a long one pauses the session, rig status
    // shows the stage back within 2 s of it answering again, and Resume completes the session.
    {"StageDriveAwayBriefly", "the drives refuse connections for 0.3 s", Expect::kRecovers, 2,
     Modbus([](auto& f) { f.outage_ms = 300; }), nullptr, "", -1, ModbusConsumed, nullptr},
    {"StageDriveComesBack", "the drives refuse connections for 8 s, then answer again",
     Expect::kPauses, 2, Modbus([](auto& f) { f.outage_ms = 8000; }), StageBackWithinTwoSeconds,
     "refused", -1, nullptr, PosesOnThePlan},
    // Storage.
    {"StorageDiskFull", "every database write fails (file-size limit: EFBIG, like a full disk)",
     Expect::kPauses, 3, [](DaemonRig& rig) { return FileSizeLimit(rig, 0); },
     [](DaemonRig& rig) { return FileSizeLimit(rig, RLIM_INFINITY); }, "disk I/O error", -1,
     nullptr, nullptr},
    {"StorageReadOnly", "the database file and its WAL become read-only (immutable)",
     Expect::kPauses, 3, [](DaemonRig& rig) { return DatabaseReadOnly(rig, true); },
     [](DaemonRig& rig) { return DatabaseReadOnly(rig, false); }, "disk I/O error", -1, nullptr,
     nullptr},
};

// The meters after the PR-650 (issue 41): brdf-sim's PR-670 and CS-2000 with their own codes
// (the PR-670's result codes, the CS-2000's ERxx), a meter that leaves remote mode (the driver is
// answered again once the rig has connected it, which re-enters remote mode) and an unplugged
// USB cable (the port vanishes during the spectrum; brief: reconnected away; long: paused until
// it is back). docs/pr670-protocol.md and docs/cs2000-protocol.md list the codes' handling.
const FaultCase kMeterMatrix[] = {
    {"Pr670TooDarkAdapted", "PR-670 result code -8 (too dark) on a light reading: exposure doubled",
     Expect::kRecovers, 0, Serial([](auto& f) {
       f.quality_code = -8;
       f.quality_count = 1;
     }),
     nullptr, "", -1, SerialConsumed, nullptr, "pr670"},
    {"Pr670SyncFailureRetried", "PR-670 result code -10 (sync failure): SS0, measured again",
     Expect::kRecovers, 2, Serial([](auto& f) {
       f.quality_code = -10;
       f.quality_count = 1;
     }),
     nullptr, "", -1, SerialConsumed, nullptr, "pr670"},
    {"Pr670UnknownCodeFails", "PR-670 result code -3 (not in the sources) on every try",
     Expect::kPauses, 2, Serial([](auto& f) {
       f.quality_code = -3;
       f.quality_count = 1000;
     }),
     ClearSerial, "code -3", -1, nullptr, nullptr, "pr670"},
    {"Pr670LeavesRemoteMode", "the PR-670 leaves remote mode (its operator pressed a key)",
     Expect::kRecovers, 2, Serial([](auto& f) { f.leave_remote = true; }), nullptr, "", -1,
     SerialAndRemoteConsumed, nullptr, "pr670"},
    {"Pr670UnpluggedBriefly", "the PR-670's USB port vanishes during report 5, back at once",
     Expect::kRecovers, 2, Serial([](auto& f) { f.vanish_seconds = 5; }), nullptr, "", -1,
     SerialConsumed, nullptr, "pr670"},
    {"Pr670Unplugged", "the PR-670's USB cable is pulled during report 5 and stays out",
     Expect::kPauses, 2, Serial([](auto& f) { f.vanish_seconds = 300; }), MeterBack, "vanished", -1,
     nullptr, nullptr, "pr670"},
    {"Cs2000OverRangeAdapted", "CS-2000 ER10 (over measurement range): integration halved",
     Expect::kRecovers, 0, Serial([](auto& f) {
       f.quality_code = 10;
       f.quality_count = 1;
     }),
     nullptr, "", -1, SerialConsumed, nullptr, "cs2000"},
    {"Cs2000AnswersErrorCodes", "CS-2000 ER83 (measurement angle abnormality) on every try",
     Expect::kPauses, 2, Serial([](auto& f) {
       f.quality_code = 83;
       f.quality_count = 1000;
     }),
     ClearSerial, "ER83", 83, nullptr, nullptr, "cs2000"},
    {"Cs2000LeavesRemoteMode", "the CS-2000 leaves remote mode", Expect::kRecovers, 2,
     Serial([](auto& f) { f.leave_remote = true; }), nullptr, "", -1, SerialAndRemoteConsumed,
     nullptr, "cs2000"},
    {"Cs2000Unplugged", "the CS-2000's port vanishes during a spectral block and stays away",
     Expect::kPauses, 2, Serial([](auto& f) { f.vanish_seconds = 300; }), MeterBack, "vanished", -1,
     nullptr, nullptr, "cs2000"},
};

// The stage on Modbus RTU (brdf-sim's RTU pty): the fault plan with Modbus faults that the bus
// retries away and ones that pause the session until cleared.
const FaultCase kRtuMatrix[] = {
    {"RtuException06Briefly", "exception 06 (busy) on the next two requests", Expect::kRecovers, 2,
     Modbus([](auto& f) {
       f.exception_code = 6;
       f.exception_count = 2;
     }),
     nullptr, "", -1, ModbusConsumed, nullptr},
    // Later than the response timeout (300 ms) but inside the RTU drain that follows it (500 ms):
    // the late reply is discarded, never read as the answer to the next request.
    {"RtuLateReplies", "the next two replies come after the response timeout", Expect::kRecovers, 2,
     Modbus([](auto& f) {
       f.late_reply_ms = 550;
       f.late_count = 2;
     }),
     nullptr, "", -1, ModbusConsumed, PosesOnThePlan},
    {"RtuException06KeepsComing", "exception 06 (busy) on every request", Expect::kPauses, 2,
     Modbus([](auto& f) {
       f.exception_code = 6;
       f.exception_count = 1000;
     }),
     ClearModbus, "busy", 6, nullptr, nullptr},
    {"RtuWordOrderMismatch", "the drives switch to lower word first mid-session", Expect::kPauses,
     2, Modbus([](auto& f) { f.swap_word_order = true; }), ClearModbus, "word_order", -1, nullptr,
     PosesOnThePlan},
};

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char ch) { return std::tolower(ch); });
  return s;
}

class FaultMatrixTest : public ::testing::TestWithParam<FaultCase> {
 protected:
  void SetUp() override {
    const char* meter = GetParam().meter;
    std::vector<std::string> args;
    if (rtu_) args.push_back("--rtu");
    if (meter != nullptr) args.insert(args.end(), {"--meter", meter});
    Status sim = rig_.StartSim(args);
    ASSERT_TRUE(sim.ok()) << sim.ToString();
    std::string toml = rtu_ ? RtuFaultConfigToml(rig_.sim(), rig_.database())
                            : FaultConfigToml(rig_.sim(), rig_.database());
    if (meter != nullptr) {
      const std::string table = "[meter]\n";
      toml.insert(toml.find(table) + table.size(),
                  "model = \"" + std::string(meter) + "\"\nchar_gap_ms = 1\n");
    }
    if (rtu_) {
      ASSERT_NE(toml.find("transport = \"rtu\""), std::string::npos) << toml;
    }
    Status daemon = rig_.StartDaemon(toml);
    ASSERT_TRUE(daemon.ok()) << daemon.ToString();
  }

  void TearDown() override {
    if (cleanup_) (void)cleanup_(rig_);
    if (op_) {
      op_->Stop();
      for (const std::string& e : op_->errors()) ADD_FAILURE() << "operator: " << e;
    }
    StopDaemonExpectingCleanExit(rig_);
  }

  // The daemon process is still there (not exited, not a zombie) and answers.
  void ExpectDaemonAlive() {
    ASSERT_NE(rig_.daemon(), nullptr);
    std::ifstream stat("/proc/" + std::to_string(rig_.daemon()->pid()) + "/stat");
    std::string pid, comm, state;
    stat >> pid >> comm >> state;
    EXPECT_TRUE(stat && state != "Z" && state != "X") << "brdfd is gone (state " << state << ")";
    v1::GetRigStatusRequest request;
    v1::RigStatus status;
    grpc::Status st = rig_.control().GetRigStatus(DaemonRig::Context().get(), request, &status);
    EXPECT_TRUE(st.ok()) << "brdfd does not answer: " << st.error_message();
  }

  std::set<std::int64_t> ReadingIds(const std::string& id) {
    Result<std::vector<v1::Reading>> r = rig_.Readings(id);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    std::set<std::int64_t> ids;
    if (r.ok()) {
      for (const auto& x : *r) ids.insert(x.id());
    }
    return ids;
  }

  // The row: the fault plan with the fault injected, then the checks of the top of the file.
  void RunRow(const FaultCase& c);

  bool rtu_ = false;  // the stage on brdf-sim's RTU pty instead of Modbus TCP
  DaemonRig rig_;
  std::unique_ptr<GrpcOperator> op_;
  Action cleanup_;
};

class FaultMatrixRtuTest : public FaultMatrixTest {
 protected:
  FaultMatrixRtuTest() { rtu_ = true; }
};

TEST_P(FaultMatrixTest, FaultIsRetriedOrPausesAndResumesWithoutLosingAReading) {
  RunRow(GetParam());
}

TEST_P(FaultMatrixRtuTest, FaultIsRetriedOrPausesAndResumesWithoutLosingAReading) {
  RunRow(GetParam());
}

void FaultMatrixTest::RunRow(const FaultCase& c) {
  SCOPED_TRACE(std::string(c.name) + ": " + c.fault);
  cleanup_ = c.clear;  // a failed assertion must not leave the fault behind (e.g. immutable)

  if (c.after_readings == 0) {
    Status injected = c.inject(rig_);
    ASSERT_TRUE(injected.ok()) << injected.ToString();
  }
  Result<v1::Session> submitted = rig_.Submit(kFaultPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  const std::int64_t sid = std::stoll(id);
  const int planned = static_cast<int>(submitted->summary().sample_readings() +
                                       submitted->summary().reference_readings() +
                                       submitted->summary().dark_readings());
  op_ = std::make_unique<GrpcOperator>(rig_, id);

  if (c.after_readings > 0) {
    const v1::Session s = rig_.WaitFor(
        id,
        [&](const v1::Session&) {
          Result<DbSessionCounts> db = CountSession(rig_.database(), sid);
          return db.ok() && db->readings >= c.after_readings;
        },
        60s);
    Status injected = c.inject(rig_);
    if (injected.code() == StatusCode::kFailedPrecondition) GTEST_SKIP() << injected.ToString();
    ASSERT_TRUE(injected.ok()) << injected.ToString();
  }

  const auto stopped = [](const v1::Session& s) {
    return s.state() == v1::SESSION_STATE_PAUSED || IsTerminal(s.state());
  };
  v1::Session s = rig_.WaitFor(id, stopped, 90s);
  ExpectDaemonAlive();

  if (c.expect == Expect::kRecovers) {
    ASSERT_EQ(s.state(), v1::SESSION_STATE_COMPLETED) << "expected the fault to be retried away\n"
                                                      << s.DebugString();
    for (const auto& e : op_->events()) {
      EXPECT_FALSE(e.has_state_changed() && e.state_changed().to() == v1::SESSION_STATE_PAUSED)
          << "paused on the way: " << e.state_changed().reason();
    }
    EXPECT_TRUE(c.consumed(rig_)) << "the injected fault never fired";
  } else {
    ASSERT_EQ(s.state(), v1::SESSION_STATE_PAUSED) << s.DebugString();
    ASSERT_TRUE(s.has_last_fault());
    EXPECT_NE(Lower(s.last_fault().reason()).find(Lower(c.reason)), std::string::npos)
        << "the pause does not name the fault: " << s.last_fault().reason();
    EXPECT_FALSE(s.last_fault().will_retry());
    if (c.device_code >= 0) {
      EXPECT_EQ(s.last_fault().device_code(), c.device_code);
    }
    // What was recorded before the fault is all there, and stays there.
    const std::set<std::int64_t> before = ReadingIds(id);
    EXPECT_GE(static_cast<int>(before.size()), c.after_readings);
    const Status cleared = c.clear(rig_);
    ASSERT_TRUE(cleared.ok()) << cleared.ToString();
    cleanup_ = nullptr;
    ExpectDaemonAlive();

    v1::ResumeSessionRequest resume;
    resume.set_session_id(id);
    v1::ResumeSessionResponse resumed;
    grpc::Status st = rig_.control().ResumeSession(DaemonRig::Context().get(), resume, &resumed);
    ASSERT_TRUE(st.ok()) << st.error_message();
    s = rig_.WaitFor(id, stopped, 90s);
    ASSERT_EQ(s.state(), v1::SESSION_STATE_COMPLETED) << s.DebugString();
    const std::set<std::int64_t> after = ReadingIds(id);
    EXPECT_TRUE(std::includes(after.begin(), after.end(), before.begin(), before.end()))
        << "a reading recorded before the fault is gone";
  }

  // The end state: every reading of the plan, once; the database intact.
  Result<std::vector<v1::Reading>> readings = rig_.Readings(id);
  ASSERT_TRUE(readings.ok()) << readings.status().ToString();
  EXPECT_EQ(static_cast<int>(readings->size()), planned);
  if (c.check_readings) c.check_readings(*readings);
  Result<DbSessionCounts> db = CountSession(rig_.database(), sid);
  ASSERT_TRUE(db.ok()) << db.status().ToString();
  EXPECT_EQ(db->state, "completed");
  EXPECT_EQ(db->steps, db->total_steps);
  EXPECT_EQ(db->steps_done, db->total_steps);
  EXPECT_EQ(db->readings, planned);
  EXPECT_EQ(db->duplicate_readings, 0);
  EXPECT_EQ(db->orphan_readings, 0);
  Result<std::string> problems = StorageProblems(rig_.database(), sid);
  ASSERT_TRUE(problems.ok()) << problems.status().ToString();
  EXPECT_EQ(*problems, "");
  ExpectDaemonAlive();
}

std::string RowName(const ::testing::TestParamInfo<FaultCase>& row) {
  return row.param.name;
}

INSTANTIATE_TEST_SUITE_P(Matrix, FaultMatrixTest, ::testing::ValuesIn(kMatrix), RowName);
INSTANTIATE_TEST_SUITE_P(Rtu, FaultMatrixRtuTest, ::testing::ValuesIn(kRtuMatrix), RowName);
INSTANTIATE_TEST_SUITE_P(Meters, FaultMatrixTest, ::testing::ValuesIn(kMeterMatrix), RowName);

}  // namespace
}  // namespace brdf::testing
