#include "app/MpiDomain.h"

#include <cstdlib>
#include <stdexcept>
#include <vector>

#ifdef REND_HAVE_MPI
#include <mpi.h>
#endif

namespace rend {

#ifdef REND_HAVE_MPI
namespace {

bool started = false;

class MpiDomain final : public sim::Domain {
public:
    MpiDomain(std::vector<sim::Slab> slabs, int rank) : Domain(std::move(slabs), rank) {}

    // This slab reads [ghostBegin, begin) from the slab below and [end, ghostEnd) from the one
    // above, and sends them what they read of it; all four transfers at once.
    void exchange(double* values, int width) override {
        const std::vector<sim::Slab>& s = slabs();
        const int r = rank();
        const sim::Slab& own = s[r];
        std::vector<MPI_Request> requests;
        auto post = [&](bool send, int from, int to, int partner, int tag) {
            MPI_Request request;
            double* at = values + std::size_t(from) * width;
            const int count = (to - from) * width;
            if (send)
                MPI_Isend(at, count, MPI_DOUBLE, partner, tag, MPI_COMM_WORLD, &request);
            else
                MPI_Irecv(at, count, MPI_DOUBLE, partner, tag, MPI_COMM_WORLD, &request);
            requests.push_back(request);
        };
        if (r + 1 < size()) {  // tag 0 travels up, 1 down
            post(false, own.end, own.ghostEnd, r + 1, 1);
            post(true, s[r + 1].ghostBegin, own.end, r + 1, 0);
        }
        if (r > 0) {
            post(false, own.ghostBegin, own.begin, r - 1, 0);
            post(true, own.begin, s[r - 1].ghostEnd, r - 1, 1);
        }
        MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
    }

    // Every process adds the same values in rank order: the same bits everywhere.
    void sum(std::span<double> values) override {
        std::vector<double> all(values.size() * size());
        MPI_Allgather(values.data(), int(values.size()), MPI_DOUBLE, all.data(), int(values.size()),
                      MPI_DOUBLE, MPI_COMM_WORLD);
        for (std::size_t k = 0; k < values.size(); ++k) {
            double total = 0.0;
            for (int r = 0; r < size(); ++r) total += all[r * values.size() + k];
            values[k] = total;
        }
    }

    void max(std::span<double> values) override {
        MPI_Allreduce(MPI_IN_PLACE, values.data(), int(values.size()), MPI_DOUBLE, MPI_MAX,
                      MPI_COMM_WORLD);
    }

    void gather(void* values, int width, int bytes, bool perBond) override {
        std::vector<int> counts(size()), displacements(size());
        for (int r = 0; r < size(); ++r) {
            const sim::Slab& s = slabs()[r];
            const int from = perBond ? offsets_[s.begin] : s.begin;
            const int to = perBond ? offsets_[s.end] : s.end;
            counts[r] = (to - from) * width * bytes;
            displacements[r] = from * width * bytes;
        }
        auto* base = static_cast<char*>(values);
        const int r = rank();
        MPI_Gatherv(r == 0 ? MPI_IN_PLACE : base + displacements[r], counts[r], MPI_BYTE, base,
                    counts.data(), displacements.data(), MPI_BYTE, 0, MPI_COMM_WORLD);
    }

    std::vector<int> offsets_;  ///< the bonds' CSR offsets, for per-bond gathers
};

}  // namespace

int startProcesses(int& argc, char**& argv) {
    const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
    if (!size || std::atoi(size) <= 1) return 1;
    MPI_Init(&argc, &argv);
    started = true;
    int count = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &count);
    return count;
}

void endProcesses() {
    if (started) MPI_Finalize();
    started = false;
}

int processRank() {
    int rank = 0;
    if (started) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank;
}

int processCount() {
    int count = 1;
    if (started) MPI_Comm_size(MPI_COMM_WORLD, &count);
    return count;
}

std::string mpiVersion() {
    char library[MPI_MAX_LIBRARY_VERSION_STRING];
    int length = 0;
    MPI_Get_library_version(library, &length);
    std::string name(library, length);
    name = name.substr(0, name.find(','));
    return name + ", " + std::to_string(processCount()) + " processes";
}

void abortProcesses(int code) {
    if (started) MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
}

std::unique_ptr<sim::Domain> makeMpiDomain(const sim::BondFamilies& bonds) {
    auto domain =
        std::make_unique<MpiDomain>(sim::partitionSlabs(bonds, processCount()), processRank());
    domain->offsets_ = bonds.offsets;
    return domain;
}

#else

int startProcesses(int&, char**&) {
    if (const char* size = std::getenv("OMPI_COMM_WORLD_SIZE"); size && std::atoi(size) > 1)
        throw std::runtime_error(
            "this rend was built without MPI, yet mpirun started it as one of several "
            "processes: install libopenmpi-dev and rebuild (scripts/build.sh)");
    return 1;
}
void endProcesses() {}
int processRank() { return 0; }
int processCount() { return 1; }
std::string mpiVersion() { return "not built (apt-get install libopenmpi-dev, then rebuild)"; }
void abortProcesses(int code) { std::exit(code); }
std::unique_ptr<sim::Domain> makeMpiDomain(const sim::BondFamilies&) { return nullptr; }

#endif

}  // namespace rend
