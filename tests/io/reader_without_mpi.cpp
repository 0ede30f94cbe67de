// Compiled into test_io (tests/io/*.cpp), no test of its own: it fails the build when reading
// a result needs MPI. The result reader's header and every header of src/serve/ are
// included here with nothing else; if any of them pulls in mpi.h, directly or through
// another header (parallel HDF5's hdf5.h includes it), MPI_VERSION is defined below.
// (src/serve/*.cpp include only these, the standard library and cpp-httplib, libpng.)
#include "io/result_reader.hpp"
#include "serve/layers.hpp"
#include "serve/pool.hpp"
#include "serve/query.hpp"
#include "serve/region.hpp"
#include "serve/server.hpp"
#include "serve/tiles.hpp"
#include "serve/view.hpp"
#include "serve/web_assets.hpp"

#ifdef MPI_VERSION
#error "a header of the result reader or of src/serve/ includes mpi.h: reading results must not need MPI"
#endif
