// Interpolation.RenderAppearance over gRPC, against a real brdfd recording from brdf-sim
// (noiseless), with an analyst's token:
//   - two images (D65, then A) of the default size, RGBA, transparent outside the disc, lit
//     pixels inside, every lit pixel's BRDF counted by where it came from;
//   - the colour is core/colorimetry's of the reflectance factor the response gives, and that
//     reflectance is π times Interpolate's BRDF at 45°:0° (when the chosen method has one);
//   - illuminant A is redder than D65;
//   - an anisotropic session is refused (FAILED_PRECONDITION, saying so);
//   - bad requests name the field (sphere_size over the cap, light, an illuminant twice); an
//     unknown session is NOT_FOUND; no token is UNAUTHENTICATED.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>

#include "core/colorimetry.h"
#include "data/cie_tables.h"
#include "tests/daemon/interpolation/rig_test.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

class DaemonAppearanceTest : public InterpolationRigTest {
 protected:
  grpc::Status Render(const v1::AppearanceRequest& request, v1::AppearanceResponse* response,
                      const char* token = kAnalystToken) {
    return rig_.interpolation().RenderAppearance(DaemonRig::Context(token).get(), request,
                                                 response);
  }
};

// Σ r / Σ b over the opaque pixels.
double RedOverBlue(const std::string& rgba) {
  double r = 0, b = 0;
  for (std::size_t i = 0; i + 3 < rgba.size(); i += 4) {
    if (static_cast<unsigned char>(rgba[i + 3]) != 255) continue;
    r += static_cast<unsigned char>(rgba[i]);
    b += static_cast<unsigned char>(rgba[i + 2]);
  }
  return r / b;
}

TEST_F(DaemonAppearanceTest, ColourAndSphereOfARecordedSession) {
  std::string id;
  ASSERT_NO_FATAL_FAILURE(Record(plans::InterpolationGrid().Retry(2, 0), &id));

  v1::AppearanceRequest request;
  request.set_session_id(id);
  request.mutable_options()->set_mirror_phi(true);
  request.mutable_options()->set_reciprocity(true);
  v1::AppearanceResponse response;
  grpc::Status st = Render(request, &response);
  ASSERT_TRUE(st.ok()) << st.error_message();
  ASSERT_EQ(response.images_size(), 2);
  EXPECT_EQ(response.images(0).illuminant(), v1::ILLUMINANT_D65);
  EXPECT_EQ(response.images(0).name(), "D65");
  EXPECT_EQ(response.images(1).illuminant(), v1::ILLUMINANT_A);
  EXPECT_EQ(response.images(1).name(), "A");

  Result<data::CieTables> cie = data::LoadCieTables(data::kDefaultColordDir);
  ASSERT_TRUE(cie.ok()) << cie.status().ToString();
  const WavelengthGrid grid{response.grid().start_nm(), response.grid().step_nm(),
                            response.grid().count()};
  Spectrum reflectance{grid, {response.reflectance().begin(), response.reflectance().end()}};
  ASSERT_EQ(reflectance.values.size(), grid.count);

  for (const v1::AppearanceImage& image : response.images()) {
    SCOPED_TRACE(image.name());
    EXPECT_EQ(image.sphere_size(), 128U);
    ASSERT_EQ(image.sphere_rgba().size(), 128U * 128U * 4U);
    EXPECT_EQ(image.sphere_rgba()[3], 0) << "a corner is outside the disc";
    EXPECT_NEAR(image.disc_pixels(), std::numbers::pi * 64 * 64, 200);
    const std::uint32_t lit = image.disc_pixels() - image.unlit_pixels();
    EXPECT_GT(lit, image.disc_pixels() / 2);
    EXPECT_EQ(image.interpolated_pixels() + image.fallback_pixels() + image.model_pixels() +
                  image.empty_pixels(),
              lit);
    EXPECT_EQ(image.empty_pixels(), 0U) << "the fill chain leaves no hole";
    std::size_t bright = 0;
    for (std::size_t i = 0; i < image.sphere_rgba().size(); i += 4) {
      const auto* p = reinterpret_cast<const unsigned char*>(image.sphere_rgba().data() + i);
      if (p[3] == 255 && p[0] + p[1] + p[2] > 60) ++bright;
    }
    EXPECT_GT(bright, lit / 4);
    EXPECT_NE(image.colour().srgb_hex(), "#000000");
    EXPECT_EQ(image.colour().srgb_hex().size(), 7U);
  }

  // The colour is colorimetry's of the reflectance factor.
  const Result<Xyz> d65 = ReflectanceToXyz(reflectance, cie->d65, cie->cmf);
  ASSERT_TRUE(d65.ok());
  const v1::AppearanceColour& c = response.images(0).colour();
  EXPECT_NEAR(c.y_tristimulus(), d65->Y, 1e-9);
  EXPECT_NEAR(c.x_tristimulus(), d65->X, 1e-9);
  EXPECT_NEAR(c.z_tristimulus(), d65->Z, 1e-9);
  EXPECT_NEAR(c.x(), d65->X / (d65->X + d65->Y + d65->Z), 1e-9);
  EXPECT_GT(c.y_tristimulus(), 0.01);

  // …and the reflectance factor is π times Interpolate's BRDF at 45°:0°.
  v1::InterpolationResult at45;
  st = Interpolate(id, Iso({45, 0, 0}), v1::INTERPOLATION_METHOD_OCTANT, v1::QUANTITY_BRDF, &at45,
                   request.options());
  ASSERT_TRUE(st.ok()) << st.error_message();
  if (at45.status() == v1::INTERPOLATION_STATUS_OK) {
    ASSERT_EQ(at45.spectrum_size(), static_cast<int>(grid.count));
    for (int k = 0; k < at45.spectrum_size(); ++k) {
      EXPECT_NEAR(reflectance.values[static_cast<std::size_t>(k)],
                  std::numbers::pi * at45.spectrum(k), 1e-12);
    }
  }

  // Illuminant A is redder than D65.
  EXPECT_GT(RedOverBlue(response.images(1).sphere_rgba()),
            1.2 * RedOverBlue(response.images(0).sphere_rgba()));

  // One illuminant, a small sphere, the light head-on: the centre is lit.
  request.set_sphere_size(16);
  request.add_illuminants(v1::ILLUMINANT_A);
  request.add_light(0);
  request.add_light(0);
  request.add_light(1);
  ASSERT_TRUE(Render(request, &response).ok());
  ASSERT_EQ(response.images_size(), 1);
  EXPECT_EQ(response.images(0).name(), "A");
  EXPECT_EQ(response.images(0).sphere_rgba().size(), 16U * 16U * 4U);
  EXPECT_EQ(response.images(0).unlit_pixels(), 0U);
}

TEST_F(DaemonAppearanceTest, AnAnisotropicSessionIsRefusedSayingSo) {
  // Three poses with a white reference, measured as an anisotropic sample (four angles).
  std::string plan = PlanFixture("anisotropic appearance")
                         .PoseList({{0, 10, 40}, {10, 20, 40}, {20, 30, 40}})
                         .Reference(true)
                         .Json();
  plan.insert(plan.find('{') + 1, "\"anisotropic\": true, ");
  std::string id;
  ASSERT_NO_FATAL_FAILURE(Record(plan, &id));

  v1::AppearanceRequest request;
  request.set_session_id(id);
  v1::AppearanceResponse response;
  const grpc::Status st = Render(request, &response);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << st.error_message();
  EXPECT_NE(st.error_message().find("anisotropic"), std::string::npos) << st.error_message();
  EXPECT_NE(st.error_message().find("isotropic sessions only"), std::string::npos)
      << st.error_message();
}

TEST_F(DaemonAppearanceTest, BadRequestsNameTheField) {
  auto expect = [&](const v1::AppearanceRequest& r, grpc::StatusCode code, const char* part) {
    v1::AppearanceResponse response;
    grpc::Status st = Render(r, &response);
    EXPECT_EQ(st.error_code(), code) << st.error_message();
    EXPECT_NE(st.error_message().find(part), std::string::npos) << st.error_message();
  };
  v1::AppearanceRequest r;
  r.set_session_id("1");
  r.set_sphere_size(513);
  expect(r, grpc::StatusCode::INVALID_ARGUMENT, "sphere_size");
  r.set_sphere_size(0);
  r.add_light(1);
  expect(r, grpc::StatusCode::INVALID_ARGUMENT, "light");
  r.add_light(0);
  r.add_light(std::nan(""));
  expect(r, grpc::StatusCode::INVALID_ARGUMENT, "light[2]");
  r.clear_light();
  r.add_illuminants(v1::ILLUMINANT_D65);
  r.add_illuminants(v1::ILLUMINANT_D65);
  expect(r, grpc::StatusCode::INVALID_ARGUMENT, "illuminants[1]");
  r.clear_illuminants();
  r.add_illuminants(static_cast<v1::Illuminant>(9));
  expect(r, grpc::StatusCode::INVALID_ARGUMENT, "illuminants[0]");
  r.clear_illuminants();
  r.set_session_id("987654");
  expect(r, grpc::StatusCode::NOT_FOUND, "987654");
  v1::AppearanceResponse response;
  grpc::Status st =
      rig_.interpolation().RenderAppearance(DaemonRig::Context("").get(), r, &response);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::UNAUTHENTICATED) << st.error_message();
}

}  // namespace
}  // namespace brdf::testing
