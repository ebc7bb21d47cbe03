// The API's numeric contract as brdf.proto documents it, over real gRPC against brdfd on
// brdf-sim. The numeric fields of every request are enumerated from the proto's descriptor
// (every method of every service, nested messages included), so a numeric field added later
// fails EveryNumericRequestFieldHasADocumentedRange until it gets a row in Ranges() below: the
// one table of documented ranges this test reads. Then, per field and per RPC that carries it,
// values at the edges of the range are accepted (the call answers as the same request without
// them does) and values just outside are refused with INVALID_ARGUMENT naming the field's path
// (e.g. "directions[0].iso.phi") and the value. Enums are numeric too: their range is their
// declared values (the highest + 1 is refused).
// Where brdf.proto documents folding instead (the four-angle form's azimuths, taken modulo 360)
// a test holds that the folded value answers as its remainder does.
//
// Not walked (left out, said here so that it is no surprise): the plan (SubmitPlan and
// ValidatePlan's `plan`), whose fields the plan validator checks and ValidatePlan reports as
// problems with JSON paths (core/plan; tests/plan).
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/daemon/raw_call.h"
#include "tests/support/daemon/rig_teardown.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::MethodDescriptor;
using google::protobuf::Reflection;
using grpc::StatusCode;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Sets `path` ("options.axis_scale", "directions.iso.phi") of `message` to `value`: messages on
// the way are created, a repeated field's element 0 is used (added when the field is empty).
void SetPath(Message& message, const std::string& path, double value) {
  const std::string::size_type dot = path.find('.');
  const std::string name = path.substr(0, dot);
  const Reflection& r = *message.GetReflection();
  const FieldDescriptor* f = message.GetDescriptor()->FindFieldByName(name);
  ASSERT_NE(f, nullptr) << message.GetDescriptor()->full_name() << " has no field " << name;
  if (dot != std::string::npos) {
    Message* inner = nullptr;
    if (f->is_repeated()) {
      inner = r.FieldSize(message, f) == 0 ? r.AddMessage(&message, f)
                                           : r.MutableRepeatedMessage(&message, f, 0);
    } else {
      inner = r.MutableMessage(&message, f);
    }
    SetPath(*inner, path.substr(dot + 1), value);
    return;
  }
  const bool add = f->is_repeated() && r.FieldSize(message, f) == 0;
  auto set = [&](auto v, auto setter, auto repeated_setter, auto adder) {
    if (!f->is_repeated()) {
      (r.*setter)(&message, f, v);
    } else if (add) {
      (r.*adder)(&message, f, v);
    } else {
      (r.*repeated_setter)(&message, f, 0, v);
    }
  };
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE:
      set(value, &Reflection::SetDouble, &Reflection::SetRepeatedDouble, &Reflection::AddDouble);
      break;
    case FieldDescriptor::CPPTYPE_FLOAT:
      set(static_cast<float>(value), &Reflection::SetFloat, &Reflection::SetRepeatedFloat,
          &Reflection::AddFloat);
      break;
    case FieldDescriptor::CPPTYPE_INT32:
      set(static_cast<std::int32_t>(value), &Reflection::SetInt32, &Reflection::SetRepeatedInt32,
          &Reflection::AddInt32);
      break;
    case FieldDescriptor::CPPTYPE_INT64:
      set(static_cast<std::int64_t>(value), &Reflection::SetInt64, &Reflection::SetRepeatedInt64,
          &Reflection::AddInt64);
      break;
    case FieldDescriptor::CPPTYPE_UINT32:
      set(static_cast<std::uint32_t>(value), &Reflection::SetUInt32, &Reflection::SetRepeatedUInt32,
          &Reflection::AddUInt32);
      break;
    case FieldDescriptor::CPPTYPE_UINT64:
      set(static_cast<std::uint64_t>(value), &Reflection::SetUInt64, &Reflection::SetRepeatedUInt64,
          &Reflection::AddUInt64);
      break;
    case FieldDescriptor::CPPTYPE_ENUM:
      set(static_cast<int>(value), &Reflection::SetEnumValue, &Reflection::SetRepeatedEnumValue,
          &Reflection::AddEnumValue);
      break;
    default:
      FAIL() << f->full_name() << " is not numeric";
  }
}

// A request prepared for a field's probes (on top of the RPC's base request).
using Prepare = std::function<void(Message&)>;

// One documented range: the values at its edges (accepted) and just outside (refused).
struct Range {
  // "<Message>.<field>", or "<Message>.<field>.<field>" where the range depends on the field that
  // holds the message.
  std::string key;
  // As brdf.proto documents it.
  std::string documented;
  std::vector<double> edges;
  std::vector<double> outside;
  // What the request needs besides the field for its range to apply (e.g. a grid format for a
  // grid's steps); nothing when empty.
  Prepare prepare;
};

// options.axis_scale of 3 values (an isotropic session's, and an export's).
void ThreeScales(Message& m) {
  const FieldDescriptor* options = m.GetDescriptor()->FindFieldByName("options");
  Message* o = m.GetReflection()->MutableMessage(&m, options);
  const FieldDescriptor* scale = o->GetDescriptor()->FindFieldByName("axis_scale");
  o->GetReflection()->ClearField(o, scale);
  for (int k = 0; k < 3; ++k) o->GetReflection()->AddDouble(o, scale, 1);
}

void GridCsv(Message& m) {
  auto& r = static_cast<v1::ExportRequest&>(m);
  r.set_format(v1::EXPORT_FORMAT_GRID_CSV);
  r.set_step_theta_i(90);
  r.set_step_theta_o(90);
  r.set_step_phi(180);
}

void Rgl(Message& m) {
  static_cast<v1::ExportRequest&>(m).set_format(v1::EXPORT_FORMAT_RGL_BSDF);
}

void DefaultLight(Message& m) {
  auto& r = static_cast<v1::AppearanceRequest&>(m);
  r.clear_light();
  for (double v : {-0.5, 0.6, 0.62}) r.add_light(v);
}

constexpr double kMaxTimestampSeconds = 253402300799;  // 9999-12-31T23:59:59Z
constexpr double kMinTimestampSeconds = -62135596800;  // 0001-01-01T00:00:00Z

// THE table: every numeric field of every request, with its documented range (brdf.proto).
const std::vector<Range>& Ranges() {
  static const std::vector<Range> table = {
      {"IsoDirection.theta_i", "[0, 90]", {0, 90}, {-0.5, 90.5}, {}},
      {"IsoDirection.theta_o", "[0, 90]", {0, 90}, {-0.5, 90.5}, {}},
      {"IsoDirection.phi", "[0, 180]", {0, 180}, {-0.5, 180.5, 320}, {}},
      {"Directions.theta_i", "[0, 90]", {0, 90}, {-0.5, 90.5}, {}},
      {"Directions.theta_o", "[0, 90]", {0, 90}, {-0.5, 90.5}, {}},
      {"Directions.phi_i",
       "(−180, 180], [−360, 360] taken modulo 360",
       {-360, 360},
       {-360.5, 360.5},
       {}},
      {"Directions.phi_o",
       "(−180, 180], [−360, 360] taken modulo 360",
       {-360, 360},
       {-360.5, 360.5},
       {}},
      {"InterpolationOptions.axis_scale",
       "(0, ∞), one per axis of the session",
       {1e-9, 1e300},
       {0, -1, kInf},
       ThreeScales},
      {"InterpolateBatchRequest.chunk_size", "0 (256) … 1024", {0, 1024}, {1025}, {}},
      {"AppearanceRequest.sphere_size", "0 (128) … 512", {0, 512}, {513}, {}},
      {"AppearanceRequest.light",
       "finite, 3 values not all 0",
       {-1e300, 1e300},
       {kInf},
       DefaultLight},
      {"ExportRequest.step_theta_i", "> 0 dividing 90; 0: 1°", {90, 0.5}, {-1, 7}, GridCsv},
      {"ExportRequest.step_theta_o", "> 0 dividing 90; 0: 1°", {90, 0.5}, {-1, 7}, GridCsv},
      {"ExportRequest.step_phi", "> 0 dividing 180; 0: 1°", {180, 0.5}, {-1, 7}, GridCsv},
      {"ExportRequest.chunk_bytes", "0 (1 MiB) … 4193280", {0, 4193280}, {4193281}, {}},
      {"ExportRequest.rgl_theta_i_count", "0 (24) or 2 … 90", {0, 2, 90}, {1, 91}, Rgl},
      {"ExportRequest.rgl_resolution", "0 (48) or 2 … 128", {0, 2, 128}, {1, 129}, Rgl},
      {"StreamReadingsRequest.after_id", "≥ 0", {0, 9e18}, {-1}, {}},
      {"ListSessionsRequest.page_size",
       "any uint32; over 1000 served as 1000",
       {0, 4294967295.0},
       {},
       {}},
      {"Timestamp.seconds",
       "0001-01-01 … 9999-12-31 (google.protobuf.Timestamp)",
       {kMinTimestampSeconds, kMaxTimestampSeconds},
       {kMinTimestampSeconds - 1, kMaxTimestampSeconds + 1},
       {}},
      {"Timestamp.nanos",
       "[0, 999999999] (google.protobuf.Timestamp)",
       {0, 999999999},
       {-1, 1e9},
       {}},
      {"AnswerPromptRequest.step_index",
       "≥ 0 (the pending prompt's Prompt.step_index)",
       {0, 2147483647.0},
       {-1},
       {}},
      {"ValidatePlanRequest.time_scale", "0 (1) or > 0, finite", {0, 1e-9, 1e300}, {-1, kInf}, {}},
  };
  return table;
}

// A numeric field as a request reaches it.
struct NumericField {
  const MethodDescriptor* method;
  std::string proto_path;  // "directions.iso.phi"
  std::string error_path;  // "directions[0].iso.phi", as an error names it
  std::string key;         // the table's key found for it ("" when none)
  const FieldDescriptor* field;
};

bool IsNumeric(const FieldDescriptor& f) {
  return f.cpp_type() != FieldDescriptor::CPPTYPE_MESSAGE &&
         f.cpp_type() != FieldDescriptor::CPPTYPE_STRING &&
         f.cpp_type() != FieldDescriptor::CPPTYPE_BOOL;
}

const Range* Find(const std::string& key) {
  for (const Range& r : Ranges()) {
    if (r.key == key) return &r;
  }
  return nullptr;
}

void Walk(const MethodDescriptor& method, const Descriptor& type, const FieldDescriptor* holder,
          const std::string& proto_path, const std::string& error_path,
          std::vector<NumericField>* out) {
  for (int i = 0; i < type.field_count(); ++i) {
    const FieldDescriptor& f = *type.field(i);
    const std::string proto = proto_path + (proto_path.empty() ? "" : ".") + f.name();
    const std::string error =
        error_path + (error_path.empty() ? "" : ".") + f.name() + (f.is_repeated() ? "[0]" : "");
    if (f.cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      // The plan is the plan validator's (see the header); a map is no request's.
      if (f.message_type() == v1::Plan::descriptor() || f.is_map()) continue;
      Walk(method, *f.message_type(), &f, proto, error, out);
      continue;
    }
    if (!IsNumeric(f)) continue;
    std::string key;
    const std::string general = type.name() + "." + f.name();
    if (holder != nullptr && Find(holder->containing_type()->name() + "." + holder->name() + "." +
                                  f.name()) != nullptr) {
      key = holder->containing_type()->name() + "." + holder->name() + "." + f.name();
    } else if (Find(general) != nullptr || f.cpp_type() == FieldDescriptor::CPPTYPE_ENUM) {
      key = general;
    }
    out->push_back({&method, proto, error, key, &f});
  }
}

std::vector<NumericField> AllNumericFields() {
  std::vector<NumericField> fields;
  for (const MethodDescriptor* m : AllMethods()) {
    Walk(*m, *m->input_type(), nullptr, "", "", &fields);
  }
  return fields;
}

TEST(ContractTableTest, EveryNumericRequestFieldHasADocumentedRange) {
  std::set<std::string> used;
  const std::vector<NumericField> fields = AllNumericFields();
  for (const NumericField& f : fields) {
    EXPECT_FALSE(f.key.empty())
        << f.method->full_name() << "'s " << f.proto_path
        << " is a numeric field without a documented range: document it in brdf.proto, check it "
           "where the request is parsed, and add its row to Ranges() in "
           "tests/daemon/security/contract_test.cc";
    used.insert(f.key);
  }
  for (const Range& r : Ranges()) {
    EXPECT_EQ(used.count(r.key), 1u) << r.key << " is no numeric field of any request any more";
    EXPECT_FALSE(r.edges.empty()) << r.key << ": no edge to probe";
  }
  // The walk reaches what it must (it would pass on an empty descriptor).
  EXPECT_GT(fields.size(), 40u);
}

// The strings a message may write `v` as.
std::vector<std::string> Spellings(double v) {
  std::vector<std::string> out;
  std::ostringstream g;
  g << v;
  out.push_back(g.str());
  out.push_back(std::to_string(v));
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e19) {
    out.push_back(std::to_string(static_cast<long long>(v)));
  }
  return out;
}

bool Mentions(const std::string& text, double v) {
  for (const std::string& s : Spellings(v)) {
    if (text.find(s) != std::string::npos) return true;
  }
  return false;
}

class ContractTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rig_ = new DaemonRig();
    Status sim = rig_->StartSim({"--noise-scale", "0"});
    ASSERT_TRUE(sim.ok()) << sim.ToString();
    Status daemon = rig_->StartDaemon();
    ASSERT_TRUE(daemon.ok()) << daemon.ToString();
    Result<v1::Session> submitted = rig_->Submit(plans::InterpolationGrid().Retry(2, 0));
    ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
    recorded_ = new std::string(submitted->session_id());
    {
      GrpcOperator op(*rig_, *recorded_);
      const v1::Session done =
          rig_->WaitForState(*recorded_, v1::SESSION_STATE_COMPLETED, std::chrono::seconds(90));
      ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
      op.Stop();
    }
    Result<v1::Session> aniso = rig_->Submit(plans::TwoAnisotropicPoses("contract aniso"));
    ASSERT_TRUE(aniso.ok()) << aniso.status().ToString();
    anisotropic_ = new std::string(aniso->session_id());
    {
      GrpcOperator op(*rig_, *anisotropic_);
      const v1::Session done =
          rig_->WaitForState(*anisotropic_, v1::SESSION_STATE_COMPLETED, std::chrono::seconds(60));
      ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
      op.Stop();
    }
    Result<v1::Session> queued = rig_->Submit(plans::OnePose(), /*start_now=*/false);
    ASSERT_TRUE(queued.ok()) << queued.status().ToString();
    queued_ = new std::string(queued->session_id());
  }
  static void TearDownTestSuite() {
    if (rig_ != nullptr) StopDaemonExpectingCleanExit(*rig_);
    delete rig_;
    delete recorded_;
    delete anisotropic_;
    delete queued_;
  }
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- brdfd log ----\n" << rig_->log() << "\n----\n";
  }

  // The RPC's request as the probes start from it: valid, on the recorded session (the queued
  // one for Control's verbs, which must not change the recorded one).
  static std::unique_ptr<Message> Base(const MethodDescriptor& method) {
    std::unique_ptr<Message> m(google::protobuf::MessageFactory::generated_factory()
                                   ->GetPrototype(method.input_type())
                                   ->New());
    const bool control = method.service()->name() == "Control";
    if (const FieldDescriptor* id = method.input_type()->FindFieldByName("session_id")) {
      m->GetReflection()->SetString(m.get(), id, control ? *queued_ : *recorded_);
    }
    if (auto* r = dynamic_cast<v1::InterpolateRequest*>(m.get())) {
      r->mutable_direction()->mutable_iso()->set_theta_i(20);
      r->mutable_direction()->mutable_iso()->set_theta_o(30);
      r->mutable_direction()->mutable_iso()->set_phi(120);
    } else if (auto* b = dynamic_cast<v1::InterpolateBatchRequest*>(m.get())) {
      b->add_directions()->mutable_iso()->set_theta_i(20);
      b->mutable_directions(0)->mutable_iso()->set_theta_o(30);
      b->mutable_directions(0)->mutable_iso()->set_phi(120);
    } else if (auto* e = dynamic_cast<v1::ExportRequest*>(m.get())) {
      e->set_format(v1::EXPORT_FORMAT_READINGS_CSV);
    } else if (auto* a = dynamic_cast<v1::AppearanceRequest*>(m.get())) {
      a->set_sphere_size(16);
    } else if (auto* v = dynamic_cast<v1::ValidatePlanRequest*>(m.get())) {
      EXPECT_TRUE(
          google::protobuf::util::JsonStringToMessage(plans::OnePose().Json(), v->mutable_plan())
              .ok());
    }
    return m;
  }

  // One call; streams are read to their first message, then cancelled.
  static RawReply Call(const MethodDescriptor& method, const Message& request) {
    return CallRaw(rig_->channel(), PathOf(method), request.SerializeAsString(),
                   std::string("Bearer ") + kOperatorToken, 60s, /*max_messages=*/1);
  }
  // What a probe's answer is compared by: OK and a first message of a stream alike are
  // "answered"; else the status code (the message may say what the value changed).
  static std::string Outcome(const RawReply& reply) {
    if (reply.status.ok() || reply.messages > 0) return "answered";
    return "code " + std::to_string(reply.status.error_code()) + " (" +
           reply.status.error_message() + ")";
  }
  static std::string Code(const std::string& outcome) { return outcome.substr(0, 8); }

  static DaemonRig* rig_;
  static std::string* recorded_;
  static std::string* anisotropic_;
  static std::string* queued_;
};

DaemonRig* ContractTest::rig_ = nullptr;
std::string* ContractTest::recorded_ = nullptr;
std::string* ContractTest::anisotropic_ = nullptr;
std::string* ContractTest::queued_ = nullptr;

// The edges and outside values of a field: the table's, or an enum's declared values.
Range RangeOf(const NumericField& f) {
  if (f.field->cpp_type() != FieldDescriptor::CPPTYPE_ENUM) return *Find(f.key);
  const google::protobuf::EnumDescriptor& e = *f.field->enum_type();
  int lo = e.value(0)->number(), hi = lo;
  for (int i = 0; i < e.value_count(); ++i) {
    lo = std::min(lo, e.value(i)->number());
    hi = std::max(hi, e.value(i)->number());
  }
  return {f.key, e.full_name(), {double(lo), double(hi)}, {double(hi + 1)}, {}};
}

TEST_F(ContractTest, ValuesAtTheEdgesAreAcceptedAndJustOutsideRefusedNamingTheField) {
  int probes = 0;
  for (const NumericField& f : AllNumericFields()) {
    if (f.key.empty()) continue;  // EveryNumericRequestFieldHasADocumentedRange says so
    const Range range = RangeOf(f);
    const std::string what =
        f.method->full_name() + " " + f.proto_path + " (" + range.documented + ")";
    std::unique_ptr<Message> base = Base(*f.method);
    if (range.prepare) range.prepare(*base);
    const std::string expected = Outcome(Call(*f.method, *base));
    for (double v : range.edges) {
      std::unique_ptr<Message> request(base->New());
      request->CopyFrom(*base);
      SetPath(*request, f.proto_path, v);
      const RawReply reply = Call(*f.method, *request);
      ++probes;
      // An enum's declared value may mean nothing here (UNSPECIFIED as a filter, a format
      // without RGL's options): refused for what it means, naming the field.
      if (f.field->cpp_type() == FieldDescriptor::CPPTYPE_ENUM &&
          reply.status.error_code() == StatusCode::INVALID_ARGUMENT) {
        EXPECT_NE(reply.status.error_message().find(f.error_path), std::string::npos)
            << what << " = " << v << ": " << reply.status.error_message();
        continue;
      }
      EXPECT_EQ(Code(Outcome(reply)), Code(expected))
          << what << " = " << v << " is inside the range: " << Outcome(reply) << " against "
          << expected;
    }
    for (double v : range.outside) {
      std::unique_ptr<Message> request(base->New());
      request->CopyFrom(*base);
      SetPath(*request, f.proto_path, v);
      const RawReply reply = Call(*f.method, *request);
      ++probes;
      const std::string& message = reply.status.error_message();
      EXPECT_EQ(reply.status.error_code(), StatusCode::INVALID_ARGUMENT)
          << what << " = " << v << ": " << Outcome(reply);
      EXPECT_NE(message.find(f.error_path), std::string::npos)
          << what << " = " << v << ": \"" << message << "\" does not name " << f.error_path;
      EXPECT_TRUE(Mentions(message, v))
          << what << " = " << v << ": \"" << message << "\" does not give the value";
    }
  }
  EXPECT_GT(probes, 150);
}

// brdf.proto: the azimuths of the four-angle form are periodic; a value in [−360, 360] answers
// as its remainder in (−180, 180] does (on an anisotropic session, where the azimuths are axes of
// the index: unfolded, 250 would be 360° away from the stored −110). The relative azimuth of
// `iso` is not folded.
TEST_F(ContractTest, FourAngleAzimuthsFoldModulo360AndIsoPhiDoesNot) {
  Result<std::vector<v1::Reading>> readings = rig_->Readings(*anisotropic_);
  ASSERT_TRUE(readings.ok()) << readings.status().ToString();
  int samples = 0;
  for (const v1::Reading& reading : *readings) {
    if (reading.kind() != v1::READING_KIND_SAMPLE) continue;
    ++samples;
    const v1::Directions& d = reading.directions();
    // The nearest reading to the reading's own azimuths moved by ±360: the reading itself, at its
    // stored azimuths.
    auto expect_the_reading = [&](double phi_i, double phi_o) {
      v1::InterpolateRequest r;
      r.set_session_id(*anisotropic_);
      r.set_method(v1::INTERPOLATION_METHOD_NEAREST);
      r.set_quantity(v1::QUANTITY_RADIANCE);
      *r.mutable_direction()->mutable_four() = d;
      r.mutable_direction()->mutable_four()->set_phi_i(phi_i);
      r.mutable_direction()->mutable_four()->set_phi_o(phi_o);
      v1::InterpolateResponse response;
      const grpc::Status st =
          rig_->interpolation().Interpolate(DaemonRig::Context().get(), r, &response);
      ASSERT_TRUE(st.ok()) << st.error_message();
      ASSERT_EQ(response.result().vertices_size(), 1);
      const v1::InterpolationVertex& v = response.result().vertices(0);
      EXPECT_EQ(v.reading_id(), reading.id())
          << "φi " << phi_i << ", φo " << phi_o << " is reading " << reading.id() << "'s ("
          << d.phi_i() << ", " << d.phi_o() << ")";
      EXPECT_EQ(v.coords(1), d.phi_i());
      EXPECT_EQ(v.coords(3), d.phi_o());
    };
    const double shift_i = d.phi_i() > 0 ? -360 : 360, shift_o = d.phi_o() > 0 ? -360 : 360;
    expect_the_reading(d.phi_i(), d.phi_o());
    expect_the_reading(d.phi_i() + shift_i, d.phi_o());
    expect_the_reading(d.phi_i(), d.phi_o() + shift_o);
    expect_the_reading(d.phi_i() + shift_i, d.phi_o() + shift_o);
  }
  EXPECT_EQ(samples, 2);
  // The probes: φ −0.5, 180.5 and 320 were folded silently; they are refused.
  for (double phi : {-0.5, 180.5, 320.0}) {
    v1::InterpolateRequest r;
    r.set_session_id(*recorded_);
    r.mutable_direction()->mutable_iso()->set_theta_i(20);
    r.mutable_direction()->mutable_iso()->set_theta_o(30);
    r.mutable_direction()->mutable_iso()->set_phi(phi);
    v1::InterpolateResponse response;
    const grpc::Status st =
        rig_->interpolation().Interpolate(DaemonRig::Context().get(), r, &response);
    EXPECT_EQ(st.error_code(), StatusCode::INVALID_ARGUMENT) << phi;
    EXPECT_NE(st.error_message().find("direction.iso.phi"), std::string::npos)
        << st.error_message();
    EXPECT_NE(st.error_message().find("[0, 180]"), std::string::npos) << st.error_message();
  }
}

// An axis_scale whose length is not the session's dimension is refused, even when an index of
// the same scales' defaults is cached (all-1 scales share it).
TEST_F(ContractTest, AxisScaleOfAnotherLengthThanTheSessionsIsRefused) {
  v1::InterpolateRequest r;
  r.set_session_id(*recorded_);
  r.mutable_direction()->mutable_iso()->set_theta_i(20);
  r.mutable_direction()->mutable_iso()->set_theta_o(30);
  r.mutable_direction()->mutable_iso()->set_phi(120);
  v1::InterpolateResponse response;
  ASSERT_TRUE(rig_->interpolation().Interpolate(DaemonRig::Context().get(), r, &response).ok());
  for (int n : {1, 2, 4}) {
    for (double scale : {1.0, 2.0}) {
      r.mutable_options()->clear_axis_scale();
      for (int k = 0; k < n; ++k) r.mutable_options()->add_axis_scale(scale);
      const grpc::Status st =
          rig_->interpolation().Interpolate(DaemonRig::Context().get(), r, &response);
      EXPECT_EQ(st.error_code(), StatusCode::INVALID_ARGUMENT) << n << " × " << scale;
      EXPECT_NE(st.error_message().find("options.axis_scale: give 3 values"), std::string::npos)
          << st.error_message();

      v1::InterpolateBatchRequest batch;
      batch.set_session_id(*recorded_);
      *batch.add_directions() = r.direction();
      *batch.mutable_options() = r.options();
      const RawReply b =
          CallRaw(rig_->channel(), "/brdf.v1.Interpolation/InterpolateBatch",
                  batch.SerializeAsString(), std::string("Bearer ") + kOperatorToken);
      EXPECT_EQ(b.status.error_code(), StatusCode::INVALID_ARGUMENT) << n << " × " << scale;
      EXPECT_EQ(b.messages, 0);

      v1::AppearanceRequest appearance;
      appearance.set_session_id(*recorded_);
      appearance.set_sphere_size(16);
      *appearance.mutable_options() = r.options();
      v1::AppearanceResponse rendered;
      const grpc::Status a = rig_->interpolation().RenderAppearance(
          DaemonRig::Context(kOperatorToken, 60s).get(), appearance, &rendered);
      EXPECT_EQ(a.error_code(), StatusCode::INVALID_ARGUMENT) << n << " × " << scale;
      EXPECT_NE(a.error_message().find("options.axis_scale"), std::string::npos)
          << a.error_message();
    }
  }
  r.mutable_options()->clear_axis_scale();
  for (int k = 0; k < 3; ++k) r.mutable_options()->add_axis_scale(1);
  EXPECT_TRUE(rig_->interpolation().Interpolate(DaemonRig::Context().get(), r, &response).ok());
}

}  // namespace
}  // namespace brdf::testing
