// Interpolation.RenderAppearance: the sample's colour and a lit sphere under CIE illuminants from
// the session's BRDF index (service_interpolation.h; core/appearance.h), and the cache of its
// answers.
#include "core/appearance.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/export/fill/chain.h"
#include "core/export/fill/session_interpolant.h"
#include "core/export/fill/spectrum_source.h"
#include "core/fit/fit.h"
#include "daemon/api/appearance_stage.h"
#include "daemon/api/interpolation.h"
#include "daemon/wire/values.h"
#include "data/cie_tables.h"

namespace brdf::daemon {
namespace {

// The longest a model fit may take when a pixel needs it (the client's deadline, if shorter).
constexpr std::chrono::seconds kLongestFit{120};

struct AppearanceSettings {
  SessionId session = 0;
  interp::Method method = interp::Method::kOctant;
  interp::Options options;
  SphereOptions sphere;
  std::vector<v1::Illuminant> illuminants;
};

// What a render holds, bytes (for the memory budget, rpc/memory_budget.h): per pixel of the
// sphere its spectrum (`bands`, the session's grid: 101 to 401) and, per illuminant, its RGBA
// twice (the image and the answer).
std::uint64_t AppearanceBytes(const AppearanceSettings& s, std::size_t bands) {
  const auto pixels = static_cast<std::uint64_t>(s.sphere.size) * s.sphere.size;
  return pixels * (bands * 8 + 2 * 4 * std::max<std::uint64_t>(1, s.illuminants.size()));
}

grpc::Status ParseAppearance(const v1::AppearanceRequest& r, AppearanceSettings* out) {
  if (grpc::Status st = ParseSessionIdField(r.session_id(), "session_id", &out->session);
      !st.ok()) {
    return st;
  }
  if (grpc::Status st = ParseMethodField(r.method(), &out->method); !st.ok()) return st;
  if (grpc::Status st = ParseInterpolationOptions(r.options(), &out->options); !st.ok()) return st;
  if (r.sphere_size() > kMaxAppearanceSphere) {
    return InvalidField("sphere_size",
                        std::to_string(r.sphere_size()) + " pixels per side; at most " +
                            std::to_string(kMaxAppearanceSphere) +
                            " (0: " + std::to_string(kDefaultAppearanceSphere) + ")");
  }
  out->sphere.size =
      static_cast<int>(r.sphere_size() == 0 ? kDefaultAppearanceSphere : r.sphere_size());
  if (r.light_size() != 0) {
    if (r.light_size() != 3) {
      return InvalidField("light",
                          "give 3 values (x right, y up, z towards the viewer) or none, "
                          "got " +
                              std::to_string(r.light_size()));
    }
    double largest = 0;
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(r.light(k))) {
        return InvalidField("light[" + std::to_string(k) + "]",
                            "must be a finite number (got " + ShortNumber(r.light(k)) + ")");
      }
      largest = std::max(largest, std::fabs(r.light(k)));
    }
    if (largest == 0) return InvalidField("light", "must not be (0, 0, 0): it is a direction");
    // Any non-zero length is a direction: scaled so that its length cannot overflow.
    for (int k = 0; k < 3; ++k) {
      out->sphere.light[static_cast<std::size_t>(k)] = r.light(k) / largest;
    }
  }
  for (int k = 0; k < r.illuminants_size(); ++k) {
    const auto i = static_cast<v1::Illuminant>(r.illuminants(k));
    const std::string field = "illuminants[" + std::to_string(k) + "]";
    if (i != v1::ILLUMINANT_D65 && i != v1::ILLUMINANT_A) {
      return InvalidField(field, "give D65 or A (got " + std::to_string(r.illuminants(k)) + ")");
    }
    if (std::find(out->illuminants.begin(), out->illuminants.end(), i) != out->illuminants.end()) {
      return InvalidField(field, std::string(v1::Illuminant_Name(i)) + " is asked twice");
    }
    out->illuminants.push_back(i);
  }
  if (out->illuminants.empty()) out->illuminants = {v1::ILLUMINANT_D65, v1::ILLUMINANT_A};
  return grpc::Status::OK;
}

CallContext FitContext(const grpc::ServerContext& context, const CancelToken& cancel) {
  const auto remaining = context.deadline() - std::chrono::system_clock::now();
  const auto timeout = std::min<std::chrono::steady_clock::duration>(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::max(remaining, std::chrono::system_clock::duration::zero())),
      kLongestFit);
  return CallContext::WithTimeout(timeout, cancel);
}

void SetColour(const SampleColour& c, v1::AppearanceColour* out) {
  out->set_x_tristimulus(c.xyz.X);
  out->set_y_tristimulus(c.xyz.Y);
  out->set_z_tristimulus(c.xyz.Z);
  out->set_x(c.xy.x);
  out->set_y(c.xy.y);
  out->set_linear_r(c.linear_srgb.r);
  out->set_linear_g(c.linear_srgb.g);
  out->set_linear_b(c.linear_srgb.b);
  out->set_srgb_hex(c.hex);
}

// The request's bytes, the same for equal requests (the cache's key).
std::string DeterministicBytes(const google::protobuf::Message& message) {
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream stream(&bytes);
    google::protobuf::io::CodedOutputStream coded(&stream);
    coded.SetSerializationDeterministic(true);
    message.SerializeToCodedStream(&coded);
  }
  return bytes;
}

// The exports' fill chain (core/export/fill/chain.h) over the cache's indexes, as the sphere's
// BRDF: the index asked for, then (another method's) the Delaunay fallback, then the model fitted
// to the samples. The last two are made only when a direction first needs them; the fallback
// answers its first few directions from the readings near each when it can prove that answer the
// whole triangulation's (NearFallback), and triangulates every reading only otherwise.
class AppearanceChain {
 public:
  AppearanceChain(IndexCache& cache, grpc::ServerContext& context, const AppearanceSettings& s,
                  const std::shared_ptr<const IndexSnapshot>& index)
      : fallback_([this, &cache, &s](const CancelToken&) -> Result<exports::SpectrumSource> {
          Result<std::shared_ptr<const IndexSnapshot>> d =
              cache.Get(s.session, Quantity::kBrdf, interp::Method::kDelaunay, s.options);
          if (!d.ok()) return d.status().WithContext("the fill chain's Delaunay fallback");
          delaunay_ = std::move(*d);
          return exports::InterpolatorSource(*delaunay_->interpolator);
        }),
        model_([this, &context,
                &index](const CancelToken& cancel) -> Result<exports::SpectrumSource> {
          Result<fit::CookTorranceFit> fitted =
              exports::FitSampleModel(*index->samples, index->grid, FitContext(context, cancel));
          if (!fitted.ok()) return fitted.status().WithContext("the fill chain's model");
          model_fit_ = std::move(*fitted);
          return exports::ModelSource(*model_fit_);
        }),
        near_fallback_(
            [&index, &s] { return interp::NearDelaunay::Create(index->samples, s.options); },
            fallback_,
            // A direction the index has no value for: the model is likely needed too
            // (a direction outside the readings' hull), so it is fitted beside the
            // fallback's work from here on.
            [this] { model_.Start(); }),
        chain_(exports::FillPolicy::kChain, Stages(s, *index)),
        source_(chain_.Source()) {}
  AppearanceChain(const AppearanceChain&) = delete;
  AppearanceChain& operator=(const AppearanceChain&) = delete;

  BrdfLookup Lookup() const {
    return [this](const IsoDirection& at, std::span<double> out) {
      return source_(at, out) == interp::InterpStatus::kOk;
    };
  }
  exports::FillTally Tally() const { return chain_.Tally(); }
  // No stage failed for a reason of this call (see LazyStage::Lasting).
  bool Lasting() const { return fallback_.Lasting() && model_.Lasting(); }
  // Why a stage could not be made: the first, and all of them ("; ").
  const std::string& FirstError() const {
    return fallback_.error().empty() ? model_.error() : fallback_.error();
  }
  std::string Errors() const {
    std::string all = fallback_.error();
    if (!model_.error().empty()) all += (all.empty() ? "" : "; ") + model_.error();
    return all;
  }

 private:
  std::vector<exports::FillChain::Stage> Stages(const AppearanceSettings& s,
                                                const IndexSnapshot& index) {
    std::vector<exports::FillChain::Stage> stages;
    stages.push_back(
        {exports::Provenance::kInterpolated, exports::InterpolatorSource(*index.interpolator)});
    if (s.method != interp::Method::kDelaunay) {
      stages.push_back({exports::Provenance::kFallback, near_fallback_.Source()});
    }
    stages.push_back({exports::Provenance::kModel, model_.Source()});
    return stages;
  }

  std::shared_ptr<const IndexSnapshot> delaunay_;
  std::optional<fit::CookTorranceFit> model_fit_;
  LazyStage fallback_;
  LazyStage model_;
  NearFallback near_fallback_;
  const exports::FillChain chain_;
  const exports::SpectrumSource source_;
};

// One illuminant's image (and, the first time, the grid and reflectance) into `response`.
// *lasting as for Render.
grpc::Status RenderImage(v1::Illuminant which, const AppearanceChain& chain,
                         const IndexSnapshot& index, const data::CieTables& cie,
                         const SphereOptions& sphere_options, v1::AppearanceResponse* response,
                         bool* lasting) {
  const bool d65 = which == v1::ILLUMINANT_D65;
  const Spectrum illuminant = d65 ? cie.d65 : CieIlluminantA(index.grid);
  const BrdfLookup brdf = chain.Lookup();
  Result<SampleColour> colour = ComputeSampleColour(brdf, index.grid, illuminant, cie.cmf);
  *lasting = chain.Lasting();
  if (!colour.ok()) {
    const std::string& why = chain.FirstError();
    return ToGrpcStatus(why.empty() ? colour.status() : colour.status().WithContext(why));
  }
  const exports::FillTally before = chain.Tally();
  Result<LitSphere> sphere = RenderLitSphere(brdf, index.grid, illuminant, cie.cmf, sphere_options);
  *lasting = chain.Lasting();
  if (!sphere.ok()) return ToGrpcStatus(sphere.status());
  const exports::FillTally after = chain.Tally();

  v1::AppearanceImage* image = response->add_images();
  image->set_illuminant(which);
  image->set_name(d65 ? "D65" : "A");
  SetColour(*colour, image->mutable_colour());
  image->set_sphere_size(static_cast<std::uint32_t>(sphere->size));
  image->set_sphere_rgba(sphere->rgba.data(), sphere->rgba.size());
  image->set_disc_pixels(static_cast<std::uint32_t>(sphere->disc_pixels));
  image->set_unlit_pixels(static_cast<std::uint32_t>(sphere->unlit_pixels));
  image->set_interpolated_pixels(
      static_cast<std::uint32_t>(after.interpolated - before.interpolated));
  image->set_fallback_pixels(static_cast<std::uint32_t>(after.fallback - before.fallback));
  image->set_model_pixels(static_cast<std::uint32_t>(after.model - before.model));
  image->set_empty_pixels(static_cast<std::uint32_t>(after.empty - before.empty));
  image->set_peak_y(sphere->peak_y);
  if (response->reflectance_size() == 0) {
    *response->mutable_grid() = ToProtoGrid(index.grid);
    response->mutable_reflectance()->Add(colour->reflectance.values.begin(),
                                         colour->reflectance.values.end());
  }
  return grpc::Status::OK;
}

// The answer from `index` (the request checked into `s`). *lasting: false when the outcome
// depends on this call (a stage of the fill chain that failed for its deadline or the store), so
// that it may be neither cached nor handed to another caller.
grpc::Status Render(IndexCache& cache, const StopSignal& stopping, grpc::ServerContext& context,
                    const AppearanceSettings& s, const data::CieTables& cie,
                    const std::shared_ptr<const IndexSnapshot>& index,
                    v1::AppearanceResponse* response, bool* lasting) {
  const AppearanceChain chain(cache, context, s, index);
  for (const v1::Illuminant which : s.illuminants) {
    if (stopping.stopped()) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                          "RenderAppearance: the daemon is shutting down; ask again once it is "
                          "back");
    }
    if (context.IsCancelled()) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "RenderAppearance: cancelled");
    }
    if (grpc::Status st = RenderImage(which, chain, *index, cie, s.sphere, response, lasting);
        !st.ok()) {
      return st;
    }
  }
  std::string detail;
  if (index->skipped > 0) {
    detail = std::to_string(index->skipped) +
             " sample reading(s) of the session left out (first: " + index->skipped_detail + ")";
  }
  if (const std::string errors = chain.Errors(); !errors.empty()) {
    detail += (detail.empty() ? "" : "; ") + errors;
  }
  response->set_detail(std::move(detail));
  return grpc::Status::OK;
}

}  // namespace

std::shared_ptr<const v1::AppearanceResponse> InterpolationService::CachedAppearance(
    const AppearanceKey& key) {
  for (auto it = appearance_cache_.begin(); it != appearance_cache_.end();) {
    if (it->index.expired()) {  // its snapshot is gone: no call can ask for it again
      it = appearance_cache_.erase(it);
      continue;
    }
    if (it->key == key) {
      appearance_cache_.splice(appearance_cache_.begin(), appearance_cache_, it);
      return appearance_cache_.front().response;
    }
    ++it;
  }
  return nullptr;
}

std::size_t InterpolationService::appearance_flights() const {
  MutexLock lock(appearance_mu_);
  return appearance_flights_.size();
}

grpc::Status InterpolationService::RenderAppearance(grpc::ServerContext* context,
                                                    const v1::AppearanceRequest* request,
                                                    v1::AppearanceResponse* response) {
  Caller caller;
  if (grpc::Status st = auth_.CallerOf(*context, &caller); !st.ok()) return st;
  // The work permit only once the answer must be rendered (Slot::Work below): a cached answer,
  // or one an identical call is rendering, takes none.
  std::unique_ptr<StreamRegistry::Slot> slot;
  if (grpc::Status st = streams_.Open(*context, &caller, "RenderAppearance", &slot); !st.ok()) {
    return st;
  }
  AppearanceSettings s;
  if (grpc::Status st = ParseAppearance(*request, &s); !st.ok()) return st;

  Result<std::shared_ptr<const IndexSnapshot>> got =
      cache_.Get(s.session, Quantity::kBrdf, s.method, s.options);
  if (!got.ok()) return ToGrpcStatus(got.status());
  const std::shared_ptr<const IndexSnapshot> index = std::move(*got);
  if (grpc::Status st = CheckOptionsFit(s.options, *index); !st.ok()) return st;
  if (index->anisotropic) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        "RenderAppearance: session " + request->session_id() +
                            " is anisotropic (measured at several dial positions); the colour "
                            "and lit sphere are rendered for isotropic sessions only");
  }

  // The cached answer, or the one an identical call is rendering, else a render of our own.
  const AppearanceKey key{index.get(), s.session, index->through_reading_id,
                          DeterministicBytes(*request)};
  std::shared_ptr<AppearanceFlight> flight;
  if (std::optional<grpc::Status> answered = AwaitAppearance(*context, key, response, &flight)) {
    return *answered;
  }
  auto rendered = std::make_shared<v1::AppearanceResponse>();
  bool lasting = false;
  grpc::Status st(grpc::StatusCode::CANCELLED, "RenderAppearance: cancelled");
  if (Result<data::CieTables> cie = data::LoadCieTables(data::kDefaultColordDir); !cie.ok()) {
    st = ToGrpcStatus(cie.status());
    lasting = true;  // the installation's: the same for every call
  } else if (grpc::Status budget = slot->Reserve(AppearanceBytes(s, index->grid.count));
             !budget.ok()) {
    st = budget;
  } else if (slot->Work() && !context->IsCancelled()) {
    ++appearance_renders_;
    st = Render(cache_, stopping_, *context, s, *cie, index, rendered.get(), &lasting);
  }
  LandAppearance(flight, index, rendered, st, lasting);
  if (st.ok()) *response = *rendered;
  return st;
}

std::optional<grpc::Status> InterpolationService::AwaitAppearance(
    grpc::ServerContext& context, const AppearanceKey& key, v1::AppearanceResponse* response,
    std::shared_ptr<AppearanceFlight>* flight) {
  MutexLock lock(appearance_mu_);
  for (;;) {
    if (std::shared_ptr<const v1::AppearanceResponse> hit = CachedAppearance(key)) {
      lock.Unlock();
      ++appearance_reuses_;
      *response = *hit;
      return grpc::Status::OK;
    }
    auto it = std::find_if(appearance_flights_.begin(), appearance_flights_.end(),
                           [&key](const auto& f) { return f->key == key; });
    if (it == appearance_flights_.end()) {
      *flight = std::make_shared<AppearanceFlight>();
      (*flight)->key = key;
      appearance_flights_.push_back(*flight);
      return std::nullopt;
    }
    const std::shared_ptr<const AppearanceFlight> other = *it;
    while (!other->done) {
      // The synchronous API has no wake-up for a cancelled call: look now and then.
      if (context.IsCancelled()) {
        return grpc::Status(grpc::StatusCode::CANCELLED, "RenderAppearance: cancelled");
      }
      if (stopping_.stopped()) {
        return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                            "RenderAppearance: the daemon is shutting down; ask again once it is "
                            "back");
      }
      appearance_done_.WaitFor(appearance_mu_, std::chrono::milliseconds(100));
    }
    // Done: the flight's outcome no longer changes.
    if (other->shared) {
      lock.Unlock();
      ++appearance_reuses_;
      if (other->status.ok()) *response = *other->response;
      return other->status;
    }
    // The other call was cancelled, or its answer held only for it: look again (a third call
    // may render it by now), else render here.
  }
}

void InterpolationService::LandAppearance(const std::shared_ptr<AppearanceFlight>& flight,
                                          const std::shared_ptr<const IndexSnapshot>& index,
                                          const std::shared_ptr<v1::AppearanceResponse>& rendered,
                                          const grpc::Status& st, bool lasting) {
  {
    MutexLock lock(appearance_mu_);
    flight->done = true;
    flight->shared = lasting && st.error_code() != grpc::StatusCode::CANCELLED;
    flight->status = st;
    if (st.ok()) flight->response = rendered;
    appearance_flights_.remove(flight);
    if (st.ok() && flight->shared) {
      appearance_cache_.push_front(AppearanceEntry{flight->key, index, rendered});
      if (appearance_cache_.size() > kAppearanceCacheEntries) appearance_cache_.pop_back();
    }
  }
  appearance_done_.NotifyAll();
}

}  // namespace brdf::daemon
