// The lines of a meter's reply: where they end, how many are complete, and the bytes as a log
// or an error message may show them. Pure: the framing layer (reply_reader.h) and every meter's
// protocol parser use these.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace brdf::drivers::serial {

// Splits a reply into lines. The meter ends lines with CR LF, but LF alone and a bare CR are also
// accepted as line ends (one quoted manual shows the D5 header "qq,U" run into the next line with
// a bare CR). Empty lines are dropped, so "CR LF" split across two reads is still one line end.
std::vector<std::string> SplitReplyLines(std::string_view reply);

// Number of non-empty lines in `bytes` that are already terminated (CR, LF or CR LF). A trailing
// bare CR counts as a line end: the framing layer only trusts the count after a quiet gap.
std::size_t CountCompleteLines(std::string_view bytes);

// True if `bytes` ends with a CR or an LF.
bool EndsWithLineEnd(std::string_view bytes);

// `bytes` for a log or an error message: printable ASCII kept, CR as \r, LF as \n, the rest as
// \xNN, cut to `max_chars` with "..." appended when longer.
std::string Printable(std::string_view bytes, std::size_t max_chars = 48);

}  // namespace brdf::drivers::serial
