// python/src/trips_py.hpp -- the shaft's memory from Python (issue 34):
// registers hoist._hoist._trips, _trip (the history database, read-only,
// hoist/history/store.hpp), _record_trips (the offline trip pipeline,
// hoist/trip_pipeline.hpp, as hoist-trips ingest runs it) and the exception
// hoist.HistoryError (history::StoreError: a database that cannot be read or
// is not ours; the message names it).  Wrapped with the docstrings in
// python/hoist/__init__.py.  Called with the GIL held; the database reads and
// the pipeline run with it released.
#pragma once

#include <pybind11/pybind11.h>

namespace hoist::python {

void bindTrips(pybind11::module_& m);

}  // namespace hoist::python
