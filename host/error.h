// The project's exception lives in the public header; internal code includes it from here.
#pragma once

#include "mcdenoise/error.h"
