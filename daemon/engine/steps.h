// The wire conversions (daemon/wire/) executor.cc uses: its steps as the API's step kinds and
// prompts, and the time of its events. The other engine files include daemon/wire/ directly;
// this header goes once executor.cc does too.
#pragma once

#include "daemon/wire/enums.h"
#include "daemon/wire/plan.h"
#include "daemon/wire/values.h"
