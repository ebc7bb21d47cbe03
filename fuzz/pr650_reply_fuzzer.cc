// Fuzz target: the PR-650 reply parser (drivers/pr650/protocol.h) and the line framing it
// rests on (drivers/serial/reply_lines.h). The input is one reply
// as it came off the wire; every parser gets it, because the meter (or line noise) can send any
// bytes in answer to any command. Beyond not crashing, each parser must keep its promises:
// lines hold no line ends and are never empty, Printable() is printable, accepted numbers are
// finite, an accepted spectrum has one value per band of its grid and matches the expected grid.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "drivers/pr650/protocol.h"
#include "drivers/serial/reply_lines.h"
#include "fuzz/fuzz_check.h"

namespace brdf::fuzz {
namespace {

using namespace brdf::drivers::pr650;
using namespace brdf::drivers::serial;

void CheckFraming(std::string_view reply) {
  const std::vector<std::string> lines = SplitReplyLines(reply);
  for (const std::string& line : lines) {
    BRDF_FUZZ_CHECK(!line.empty(), "SplitReplyLines returned an empty line");
    BRDF_FUZZ_CHECK(line.find_first_of("\r\n") == std::string::npos,
                    "a line holds a line end: \"" + Printable(line) + "\"");
  }
  const std::size_t complete = CountCompleteLines(reply);
  BRDF_FUZZ_CHECK(complete <= lines.size(), "more complete lines than lines");
  if (EndsWithLineEnd(reply)) {
    BRDF_FUZZ_CHECK(complete == lines.size(),
                    "a reply ending in a line end has " + std::to_string(lines.size()) +
                        " lines but CountCompleteLines says " + std::to_string(complete));
  }
  const std::string shown = Printable(reply, 48);
  for (char c : shown) {
    const auto u = static_cast<unsigned char>(c);
    BRDF_FUZZ_CHECK(u >= 0x20 && u <= 0x7e, "Printable() returned a non-printable byte");
  }
  // Cut at 48 characters, plus one escape (\xNN) begun before the cut, plus "...".
  BRDF_FUZZ_CHECK(shown.size() <= 48 + 3 + 3, "Printable() ignored max_chars");
}

void CheckSpectrum(const Result<SpectrumReply>& r, std::optional<WavelengthGrid> expected) {
  if (!r.ok()) return;
  BRDF_FUZZ_CHECK(r->values.size() == r->grid.count, "values do not match the grid's band count");
  BRDF_FUZZ_CHECK(r->grid.count >= 2 && r->grid.step_nm > 0, "accepted a degenerate grid");
  BRDF_FUZZ_CHECK(std::isfinite(r->integrated), "accepted a non-finite integrated intensity");
  for (double v : r->values) BRDF_FUZZ_CHECK(std::isfinite(v), "accepted a non-finite value");
  if (expected) {
    BRDF_FUZZ_CHECK(r->grid.count == expected->count, "band count differs from the layout");
    BRDF_FUZZ_CHECK(std::abs(r->grid.start_nm - expected->start_nm) <= 0.01 &&
                        std::abs(r->grid.step_nm - expected->step_nm) <= 0.01,
                    "accepted a spectrum whose grid differs from the layout");
  }
}

}  // namespace

int FuzzPr650Reply(const std::uint8_t* data, std::size_t size) {
  const std::string_view reply = AsText(data, size);
  CheckFraming(reply);

  if (auto n = ParseNumber(reply)) BRDF_FUZZ_CHECK(std::isfinite(*n), "ParseNumber: not finite");
  if (auto s = ParseStatusReply(reply, "M0"); s.ok()) {
    // "-1" is the meter's own "no measurement" report (kNoMeasurementStatus), accepted on purpose.
    BRDF_FUZZ_CHECK((*s >= 0 && *s <= 999) || *s == kNoMeasurementStatus,
                    "status code outside 0-999 and not the no-measurement -1");
  }
  if (auto s = ParseSetupReply(reply); s.ok()) (void)DescribeSetupReply(*s);
  if (auto f = ParseFlickerReply(reply); f.ok()) {
    BRDF_FUZZ_CHECK(std::isfinite(f->frequency_hz), "flicker frequency not finite");
  }
  if (auto c = ParseColorimetryReply(reply); c.ok()) {
    BRDF_FUZZ_CHECK(std::isfinite(c->luminance) && std::isfinite(c->x) && std::isfinite(c->y),
                    "colorimetry not finite");
  }
  if (auto t = ParseTristimulusReply(reply); t.ok()) {
    BRDF_FUZZ_CHECK(std::isfinite(t->X) && std::isfinite(t->Y) && std::isfinite(t->Z),
                    "tristimulus not finite");
  }
  if (auto s = ParseSerialNumberReply(reply); s.ok()) {
    BRDF_FUZZ_CHECK(s->find_first_of("\r\n") == std::string::npos, "serial number holds a CR/LF");
  }

  if (auto layout = ParseLayoutReply(reply); layout.ok()) {
    const WavelengthGrid g = layout->grid();
    BRDF_FUZZ_CHECK(g.valid() && g.count >= 2, "accepted a layout with an invalid grid");
    BRDF_FUZZ_CHECK(std::abs(g.last_nm() - layout->last_nm) <= 0.01 + 1e-9 * layout->last_nm,
                    "accepted a layout whose last wavelength does not follow");
  }

  CheckSpectrum(ParseSpectrumReply(reply), std::nullopt);
  CheckSpectrum(ParseSpectrumReply(reply, WavelengthGrid::Pr650()), WavelengthGrid::Pr650());
  // A D5 report whose length matches a small grid; the grid's start and step come from the
  // report's own third line when it has one, so the comparison path is reached too.
  const std::vector<std::string> lines = SplitReplyLines(reply);
  if (lines.size() >= 4) {
    WavelengthGrid small{380, 4, lines.size() - 2};
    CheckSpectrum(ParseSpectrumReply(reply, small), small);
  }
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzPr650Reply)
