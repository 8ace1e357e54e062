#pragma once
/// \file
/// What the fuzz targets of the estimator's readers and of the model checksum run and check
/// (docs/fuzzing.md): the vehicle JSON reader (`fuzz_vehicle`), the quadrotor data-folder reader
/// (`fuzz_quadrotor_data`) and byte mutations of written models (`fuzz_model`, after
/// CheckModelInput). Each returns the violated property (with the input) or nullopt; the targets trap
/// on a violation and tests/estim/fuzz_regression_test.cc replays tests/data/fuzz/{vehicle,
/// quadrotor_data,model} through the same functions. They need the library only.

#include <optional>
#include <string>
#include <string_view>

namespace cheval::fuzz {

/// The bytes as a vehicle file: estim::ReadVehicle throws InputError beginning with the path, or
/// gives a vehicle that ValidateVehicle accepts, whose values are finite and whose VehicleToJson
/// reads back to the same values.
std::optional<std::string> CheckVehicleInput(std::string_view data);

/// Byte 0 picks a file of a small valid data folder (landmarks, measurements, initial, truth,
/// vehicle: byte % 5); the rest of the bytes replace it. estim::ReadQuadrotorData throws InputError
/// beginning with the folder's path, or gives data within the documented bounds: finite values,
/// landmark ids in range, measurement times not decreasing, initial and truth times increasing, unit
/// quaternions, at least 2 initial poses.
std::optional<std::string> CheckQuadrotorDataInput(std::string_view data);

/// The bytes as a model text re-read as version 1 (its checksum removed, so the structure is
/// fuzzed past the checksum). When that gives a model, its written text (version 2, with checksum)
/// with one byte changed (position and value from the input's last bytes) must be refused with an
/// InputError or evaluate bit-identically at the start, middle and end of every segment.
std::optional<std::string> CheckModelMutationInput(std::string_view data);

}  // namespace cheval::fuzz
