// The planar float image lives in the public header; internal code includes it from here.
#pragma once

#include "mcdenoise/image.h"
