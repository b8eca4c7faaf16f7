#pragma once
/// @file
/// Umbrella header of the CoReDEM coupling protocol v1 (docs/protocol.md).

#include <coredem/protocol/fields.h>
#include <coredem/protocol/message.h>
#include <coredem/protocol/multipart_file.h>
#include <coredem/protocol/status.h>
#include <coredem/protocol/transport.h>
#include <coredem/protocol/validate.h>
#include <coredem/protocol/version.h>
