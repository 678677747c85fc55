// Forwarding header, kept only because factors/point.h (package C) includes it
// for camera::ChainToCam: the camera factors live in factors/camera/.
// Remove once point.h includes "boxplus/factors/camera/models.h".
#pragma once

#include "boxplus/factors/camera/models.h"
#include "boxplus/factors/camera/point_projection.h"
