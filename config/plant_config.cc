#include "core/plant.h"
