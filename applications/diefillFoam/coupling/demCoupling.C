#include "demCoupling.H"
#include "dragForce.H"
#include "checkKeywords.H"
#include "fvm.H"
#include "fvc.H"
#include "mathematicalConstants.H"
#include "sigFpe.H"
#include "vectorIOField.H"
#include "treeDataCell.H"
#include "clockValue.H"

#include "demLib/case_lock.hpp"
#include "demLib/case_runner.hpp"
#include "demLib/case_setup.hpp"
#include "demLib/config.hpp"
#include "demLib/error.hpp"
#include "demLib/hdf5_file.hpp"
#include "demLib/version.hpp"
#if DEMLIB_HAS_MPI
#include "demLib/communicator_mpi.hpp"
#endif

#include <cmath>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <tuple>
#include <type_traits>
#include <unordered_map>

// Defined in demLib (src/demLib/src/version.cpp): the version of the library
// actually loaded, as opposed to dem::versionString of the headers.
namespace dem
{
    const char* libraryVersion();
}

// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::diefill::demCoupling::checkLibraryVersion()
{
    // A stale libdemLib.so on LD_LIBRARY_PATH would silently mix versions
    if (std::strcmp(dem::libraryVersion(), dem::versionString) != 0)
    {
        FatalErrorInFunction
            << "diefillFoam was compiled against demLib "
            << dem::versionString << " but loaded demLib "
            << dem::libraryVersion() << " at run time." << nl
            << "    Rebuild with ./Allwmake and source etc/bashrc."
            << exit(FatalError);
    }
}


template<class Type>
Foam::Field<Type> Foam::diefill::demCoupling::localAverage
(
    const UList<Type>& cellValues
) const
{
    Field<Type> result(cells_.size(), Zero);
    forAll(cells_, i)
    {
        forAll(cells_[i], k)
        {
            result[i] += weights_[i][k]*cellValues[cells_[i][k]];
        }
    }
    return result;
}


template<class... Types>
std::tuple<Foam::Field<Types>...> Foam::diefill::demCoupling::averageToParticles
(
    const UList<Types>&... cellValues
) const
{
    // Serially each particle's cells are all here: the sums are complete
    std::tuple<Field<Types>...> local(localAverage(cellValues)...);
    if (!decomposed_)
    {
        return local;
    }

    // Decomposed: each visitor's shares of every field back to its owner in
    // one message per rank, summed in rank order
    const label width = (label(pTraits<Types>::nComponents) + ...);
    const label nVisitors = cells_.size();
    std::vector<double> shares(std::size_t(nVisitors)*width);
    label offset = 0;
    auto pack = [&](const auto& field)
    {
        using Type = typename std::decay_t<decltype(field)>::value_type;
        for (label v = 0; v < nVisitors; ++v)
        {
            for (direction c = 0; c < pTraits<Type>::nComponents; ++c)
            {
                shares[std::size_t(v)*width + offset + c] = component(field[v], c);
            }
        }
        offset += pTraits<Type>::nComponents;
    };
    std::apply([&](const auto&... fields) { (pack(fields), ...); }, local);

    const std::vector<double> sums = routing_->sumToOwners(shares, width);
    const label n = nOwned();
    std::tuple<Field<Types>...> owned;
    offset = 0;
    auto unpack = [&](auto& field)
    {
        using Type = typename std::decay_t<decltype(field)>::value_type;
        field.setSize(n);
        for (label i = 0; i < n; ++i)
        {
            for (direction c = 0; c < pTraits<Type>::nComponents; ++c)
            {
                setComponent(field[i], c) = sums[std::size_t(i)*width + offset + c];
            }
        }
        offset += pTraits<Type>::nComponents;
    };
    std::apply([&](auto&... fields) { (unpack(fields), ...); }, owned);
    return owned;
}


Foam::diefill::particleFluidState Foam::diefill::demCoupling::state
(
    label i,
    const vector& fluidVelocity,
    scalar voidFraction,
    const vector& pressureGradient
) const
{
    const auto& particles = runner_->simulation().particles();
    const scalar r = particles.radius[i];
    const auto& v = particles.velocity[i];

    particleFluidState s;
    s.diameter = 2*r/coarseGrainFactor_;
    s.volume = 4.0/3.0*constant::mathematical::pi*pow3(r);
    s.particleVelocity = vector(v.x(), v.y(), v.z());
    s.fluidVelocity = fluidVelocity;
    s.voidFraction = voidFraction;
    s.pressureGradient = pressureGradient;
    s.fluidDensity = rho_;
    s.fluidViscosity = mu_;
    s.gravity = g_.value();
    s.model = model_;
    return s;
}


void Foam::diefill::demCoupling::checkTimeSteps(scalar demDt) const
{
    // The exchange is once per fluid step of a whole number of DEM steps: an
    // adjusted step would break that at its first change, after the run had
    // begun writing.
    if (mesh_.time().controlDict().getOrDefault<Switch>("adjustTimeStep", false))
    {
        FatalIOErrorInFunction(mesh_.time().controlDict())
            << "adjustTimeStep yes: diefillFoam runs with a fixed deltaT,"
            << " an integer multiple of the DEM time step (simulation/timeStep "
            << demDt << " s, constant/demProperties); expected"
            << " adjustTimeStep no" << exit(FatalIOError);
    }
    const scalar fluidDt = mesh_.time().deltaTValue();
    if (!(fluidDt > 0))
    {
        FatalIOErrorInFunction(mesh_.time().controlDict())
            << "deltaT must be > 0, got " << fluidDt << exit(FatalIOError);
    }
    const label n = label(std::round(fluidDt/demDt));

    if (n < 1 || mag(n*demDt - fluidDt) > 1e-6*fluidDt)
    {
        FatalErrorInFunction
            << "The fluid time step (deltaT " << fluidDt
            << " s, system/controlDict) must be an integer multiple of the"
            << " DEM time step (simulation/timeStep " << demDt
            << " s, constant/demProperties)." << exit(FatalError);
    }
}


Foam::label Foam::diefill::demCoupling::demStepsPerFluidStep() const
{
    const scalar demDt = runner_->simulation().timeStep();
    checkTimeSteps(demDt);
    return label(std::round(mesh_.time().deltaTValue()/demDt));
}


namespace
{

// The log lines' figures of a coupling step in one reduction over the ranks:
// the sum of each of the first N - nMin entries, the least of the last nMin
template<unsigned N, unsigned nMin>
struct sumThenMinOp
{
    Foam::FixedList<Foam::scalar, N> operator()
    (
        const Foam::FixedList<Foam::scalar, N>& a,
        const Foam::FixedList<Foam::scalar, N>& b
    ) const
    {
        Foam::FixedList<Foam::scalar, N> result;
        for (unsigned k = 0; k < N; ++k)
        {
            result[k] = k + nMin < N ? a[k] + b[k] : Foam::min(a[k], b[k]);
        }
        return result;
    }
};

} // End anonymous namespace


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::diefill::demCoupling::demCoupling
(
    const volVectorField& U,
    const volScalarField& p,
    volScalarField& alpha,
    const singlePhaseTransportModel& transport
)
:
    mesh_(U.mesh()),
    U_(U),
    p_(p),
    alpha_(alpha),
    dict_
    (
        IOobject
        (
            "couplingProperties",
            mesh_.time().constant(),
            mesh_,
            IOobject::MUST_READ_IF_MODIFIED,
            IOobject::NO_WRITE
        )
    ),
    model_(momentumCouplingModel::A),
    rho_(dimensionedScalar("rho", dimDensity, transport).value()),
    mu_(0),
    alphaMin_(dict_.get<scalar>("alphaMin")),
    smoothingLength_(dict_.getOrDefault<scalar>("smoothingLength", 0)),
    g_("g", dimAcceleration, Zero),
    coarseGrainFactor_(1),
    decomposed_(Pstream::parRun()),
    K_(),
    nLost_(0),
    restartForces_(false)
{
    checkLibraryVersion();

    Info<< "DEM coupling (constant/couplingProperties)" << nl
        << "    demLib version: " << dem::libraryVersion() << endl;

    const word modelType(dict_.get<word>("modelType"));
    if (modelType == "A")
    {
        model_ = momentumCouplingModel::A;
    }
    else if (modelType == "B")
    {
        model_ = momentumCouplingModel::B;
    }
    else
    {
        FatalIOErrorInFunction(dict_)
            << "Unknown modelType " << modelType
            << ", valid types are: A B" << exit(FatalIOError);
    }

    if (alphaMin_ <= 0 || alphaMin_ >= 1)
    {
        FatalIOErrorInFunction(dict_)
            << "alphaMin must lie in (0, 1), got " << alphaMin_
            << exit(FatalIOError);
    }

    // Air viscosity: laminar transport, uniform (Newtonian).  A zero or
    // negative nu or rho ended in a floating point exception (or a bead
    // falling at -667 m/s) instead of an error.
    const scalar nuMin = gMin(transport.nu()().primitiveField());
    if (!(rho_ > 0) || !(nuMin > 0))
    {
        FatalErrorInFunction
            << "constant/transportProperties: the air needs rho > 0 [kg/m3]"
            << " and nu > 0 [m2/s], got rho " << rho_ << ", nu " << nuMin
            << exit(FatalError);
    }
    mu_ = rho_*gMax(transport.nu()().primitiveField());

    voidFraction_ = voidFractionModel::New
    (
        dict_.get<word>("voidFractionModel"),
        mesh_,
        dict_
    );

    // Each model once, and one drag law: two are added (a repeated or a
    // second law doubled the drag without a word); none couples nothing.
    const wordList forceNames(dict_.get<wordList>("forceModels"));
    if (forceNames.empty())
    {
        FatalIOErrorInFunction(dict_)
            << "forceModels is empty; expected a drag law and, usually,"
            << " pressureGradient, e.g. (GidaspowErgunWenYu pressureGradient);"
            << " models: "
            << particleForce::dictionaryConstructorTablePtr_->sortedToc()
            << exit(FatalIOError);
    }
    forces_.setSize(forceNames.size());
    word dragName;
    forAll(forceNames, i)
    {
        if (forceNames.find(forceNames[i]) != i)
        {
            FatalIOErrorInFunction(dict_)
                << "forceModels names " << forceNames[i] << " twice;"
                << " expected each model once" << exit(FatalIOError);
        }
        forces_.set(i, particleForce::New(forceNames[i], dict_));
        if (isA<dragForce>(forces_[i]))
        {
            if (!dragName.empty())
            {
                FatalIOErrorInFunction(dict_)
                    << "forceModels holds two drag laws, " << dragName
                    << " and " << forceNames[i] << "; expected one"
                    << exit(FatalIOError);
            }
            dragName = forceNames[i];
        }
    }

    // Every keyword is one the solver reads; a <model>Coeffs block of a model
    // not selected now may stay (switching models is an edit of one line).
    {
        wordList known
        ({
            "modelType", "alphaMin", "smoothingLength", "voidFractionModel",
            "forceModels"
        });
        for (const word& name : particleForce::dictionaryConstructorTablePtr_->sortedToc())
        {
            known.append(name + "Coeffs");
        }
        for (const word& name : voidFractionModel::dictionaryConstructorTablePtr_->sortedToc())
        {
            known.append(name + "Coeffs");
        }
        checkKeywords(dict_, known);
    }
    if (smoothingLength_ < 0)
    {
        FatalIOErrorInFunction(dict_)
            << "smoothingLength must be >= 0 (0: no smoothing), got "
            << smoothingLength_ << exit(FatalIOError);
    }

    // The DEM: the whole case on every rank (see the class description).
    const fileName caseDir = mesh_.time().globalPath();
    // One run at a time in a case: a second one would write over the first
    // one's time folders and DEM output.  Taken before anything is written.
    if (Pstream::master())
    {
        try
        {
            caseLock_.reset(new dem::CaseLock(caseDir, "diefillFoam"));
        }
        catch (const std::exception& e)
        {
            FatalErrorInFunction
                << e.what() << exit(FatalError);
        }
    }
    dem::CaseSetup setup;
    try
    {
        setup = dem::readCaseSetup(caseDir);
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "Reading the DEM case " << caseDir/"constant/demProperties"
            << " failed:" << nl << "    " << e.what() << exit(FatalError);
    }

    // The time steps are checked before the DEM starts and opens its output:
    // a refused run leaves the results of an earlier one as they were.
    checkTimeSteps(setup.settings.timeStep);

    if (setup.endTime < mesh_.time().endTime().value() - SMALL)
    {
        FatalErrorInFunction
            << "The DEM ends (simulation/endTime " << setup.endTime
            << " s, constant/demProperties) before the air (endTime "
            << mesh_.time().endTime().value() << " s, system/controlDict)."
            << exit(FatalError);
    }

    coarseGrainFactor_ = setup.coarseGrain.factor;
    if (coarseGrainFactor_ != 1)
    {
        Info<< "    coarse grain: factor " << coarseGrainFactor_
            << ", drag of parcels = " << coarseGrainFactor_
            << "^3 x drag of primary particles of diameter D/"
            << coarseGrainFactor_ << endl;
    }

    demRestartDir_ = caseDir/fileName(setup.output.directory)/"restart";
    dem::RunOptions options;
    options.progressInterval = 0;
    if (decomposed_)
    {
        // The DEM over the same ranks as the air, on a communicator of its
        // own (its messages never meet OpenFOAM's); rank 0 writes its output.
#if DEMLIB_HAS_MPI
        MPI_Comm demComm = MPI_COMM_NULL;
        MPI_Comm_dup(MPI_COMM_WORLD, &demComm);
        options.communicator = dem::communicatorFromMpi(demComm);
#else
        FatalErrorInFunction
            << "-parallel needs demLib built with MPI (install/include/demLib/"
            << "config.hpp says it was not): rebuild with ./Allwmake"
            << exit(FatalError);
#endif
        // OpenFOAM builds the tet decomposition and the cell search tree on
        // first use, with collectives: a rank with no particle in its cells
        // would never get there and the others would wait for it (the
        // deadlock of the replicated DEM).  Built here, on every rank.
        (void)mesh_.tetBasePtIs();
        (void)mesh_.cellTree();
        routing_.reset
        (
            new particleRouting
            (
                options.communicator,
                mesh_.nCells() ? treeBoundBox(mesh_.points()) : treeBoundBox(boundBox::invertedBox)
            )
        );
    }
    const scalar startTime = mesh_.time().startTime().value();
    if (startTime <= 0)
    {
        // A new run in a case that holds a run already would overwrite part of
        // it and keep the rest: the later time folders and DEM restart files of
        // the old run, which a continuation would then take up with the new
        // inputs.
        DynamicList<word> later;
        for (const instant& t : mesh_.time().times())
        {
            if (t.value() > startTime) later.append(t.name());
        }
        const fileName demLatest =
            caseDir/fileName(setup.output.directory)/"restart"/"latest";
        if (later.size() || isFile(demLatest))
        {
            std::string found;
            for (const word& t : later)
            {
                found += (found.empty() ? "time folders " : " ") + t;
            }
            if (isFile(demLatest))
            {
                found += std::string(found.empty() ? "" : ", ")
                    + "DEM restart files in " + setup.output.directory + "/restart";
            }
            FatalErrorInFunction
                << "The case holds the results of an earlier run (" << found.c_str()
                << "); a new run from t = " << startTime << " would overwrite"
                << " part of it and leave the rest." << nl
                << "    Expected a case without them: continue the run with"
                << " startFrom latestTime (system/controlDict), or remove them"
                << " first (foamListTimes -rm; rm -r "
                << setup.output.directory << ")." << exit(FatalError);
        }
    }
    else
    {
        // The DEM restart file of the step at the air's start time (demLib
        // names them restart_<step>.h5), not merely the newest one: a run
        // continued from an earlier fluid time must find its own.
        const label step = label(std::round(startTime/setup.settings.timeStep));
        std::ostringstream name;
        name<< "restart_" << std::setw(9) << std::setfill('0') << step << ".h5";
        const fileName restartFile =
            caseDir/fileName(setup.output.directory)/"restart"/name.str();
        if (!isFile(restartFile))
        {
            FatalErrorInFunction
                << "The air starts at " << startTime << " s (DEM step "
                << step << ") but there is no DEM restart file "
                << restartFile << nl
                << "    Write restart files at the fluid write times"
                << " (output/restartInterval in constant/demProperties)."
                << exit(FatalError);
        }
        options.restartFrom = restartFile;
    }

    nullLog_.reset(new std::ostream(nullptr));
    std::ostream& log = Pstream::master() ? std::cout : *nullLog_;

    try
    {
        // demLib relies on IEEE arithmetic without traps (unbounded boxes of
        // plane walls are infinite); its OpenMP threads inherit the trapping
        // state of this thread when the pool is created, here or below.
        sigFpe::ignore noTrapping;
        runner_.reset(new dem::CaseRunner(std::move(setup), options, log));
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "Starting the DEM failed:" << nl << "    " << e.what()
            << exit(FatalError);
    }

    const scalar demTime = runner_->simulation().time();
    if (mag(demTime - mesh_.time().value()) > 1e-9 + 1e-6*demTime)
    {
        FatalErrorInFunction
            << "The DEM is at time " << demTime << " s but the air starts at "
            << mesh_.time().value() << " s: restart both from the same time."
            << exit(FatalError);
    }

    // The fluid forces the particles had at the restart time (written with
    // the air fields, see write()): with them the continued run repeats the
    // uninterrupted one.  The DEM restart file holds the forces of the
    // interval before, so they are not taken from there.
    if (startTime > 0)
    {
        IOobject forcesHeader
        (
            "particleForces",
            mesh_.time().timeName(),
            "uniform",
            mesh_,
            IOobject::MUST_READ,
            IOobject::NO_WRITE
        );
        if (decomposed_)
        {
            readForcesById(options.restartFrom + ".forces");
        }
        else if (forcesHeader.typeHeaderOk<vectorIOField>(true))
        {
            const vectorIOField forces(forcesHeader);
            auto& particles = runner_->simulation().particles();
            if (forces.size() != label(particles.size()))
            {
                FatalErrorInFunction
                    << forcesHeader.objectPath() << " holds " << forces.size()
                    << " forces but the DEM restart file "
                    << particles.size() << " particles." << exit(FatalError);
            }
            forAll(forces, i)
            {
                particles.externalForce[i] =
                    dem::Vec3(forces[i].x(), forces[i].y(), forces[i].z());
            }
            restartForces_ = true;
            restartForcesFile_ = forcesHeader.objectPath();
        }
    }

    const auto& gDem = runner_->setup().settings.gravity;
    g_.value() = vector(gDem.x(), gDem.y(), gDem.z());

    Info<< "    modelType:      " << modelType << nl
        << "    air density:    " << rho_ << " kg/m3" << nl
        << "    air viscosity:  " << mu_ << " Pa s" << nl
        << "    gravity (DEM):  " << g_.value() << " m/s2" << nl
        << "    alphaMin:       " << alphaMin_ << nl
        << "    DEM time step:  " << runner_->simulation().timeStep() << " s"
        << nl
        << "    DEM steps per fluid step: " << demStepsPerFluidStep() << nl
        << "    fluid cells:    "
        << returnReduce(mesh_.nCells(), sumOp<label>()) << nl
        << "    particles:      " << nParticles() << nl << endl;

    updateVoidFraction();
    alpha_.oldTime();
}


Foam::diefill::demCoupling::~demCoupling()
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::label Foam::diefill::demCoupling::nOwned() const
{
    return runner_->simulation().ownedCount();
}


Foam::label Foam::diefill::demCoupling::nParticles() const
{
    return decomposed_ ? returnReduce(nOwned(), sumOp<label>()) : nOwned();
}


std::string Foam::diefill::demCoupling::forcesFileOfNow() const
{
    const label step =
        label(std::round(mesh_.time().value()/runner_->simulation().timeStep()));
    std::ostringstream name;
    name<< "restart_" << std::setw(9) << std::setfill('0') << step << ".h5.forces";
    return demRestartDir_ + "/" + name.str();
}


void Foam::diefill::demCoupling::writeForcesById() const
{
    // Every rank's (id, force) to rank 0, which writes them in rank order
    const auto& particles = runner_->simulation().particles();
    const dem::Communicator& comm = runner_->simulation().decomposition()->communicator();
    std::vector<std::vector<char>> send(comm.size());
    for (label i = 0; i < nOwned(); ++i)
    {
        const double record[4] =
        {
            double(particles.id[i]),
            particles.externalForce[i].x(),
            particles.externalForce[i].y(),
            particles.externalForce[i].z()
        };
        const char* bytes = reinterpret_cast<const char*>(record);
        send[0].insert(send[0].end(), bytes, bytes + sizeof record);
    }
    const auto received = comm.exchange(send);
    std::string failure;
    if (comm.rank() == 0)
    {
        std::vector<std::int64_t> ids;
        std::vector<dem::Vec3> forces;
        for (const auto& part : received)
        {
            std::vector<double> d(part.size()/sizeof(double));
            if (!d.empty()) std::memcpy(d.data(), part.data(), part.size());
            for (std::size_t k = 0; k + 3 < d.size(); k += 4)
            {
                ids.push_back(std::int64_t(d[k]));
                forces.emplace_back(d[k + 1], d[k + 2], d[k + 3]);
            }
        }
        const std::string file = forcesFileOfNow();
        try
        {
            {
                dem::Hdf5File f(file + ".writing", dem::Hdf5File::Mode::Create);
                f.setAttribute("time", mesh_.time().value());
                f.sealAttributes();
                f.write("id", ids);
                f.write("force", forces);
            }
            if (std::rename((file + ".writing").c_str(), file.c_str()) != 0)
            {
                failure = "cannot rename " + file + ".writing";
            }
        }
        catch (const std::exception& e)
        {
            failure = e.what();
        }
    }
    if (comm.anyTrue(!failure.empty()))
    {
        FatalErrorInFunction
            << "Writing the particle forces failed"
            << (failure.empty() ? std::string(" on rank 0") : ": " + failure).c_str()
            << exit(FatalError);
    }
}


void Foam::diefill::demCoupling::readForcesById(const std::string& file)
{
    // Rank 0 reads and hands every rank all of them (once, at the start);
    // each takes its own particles' by id.
    const dem::Communicator& comm = runner_->simulation().decomposition()->communicator();
    std::vector<char> all;
    std::string failure;
    bool present = false;
    if (comm.rank() == 0 && isFile(file))
    {
        present = true;
        try
        {
            dem::Hdf5File f(file, dem::Hdf5File::Mode::Read);
            f.checkAttributes();
            const std::vector<std::int64_t> ids = f.readInt64("id");
            const std::vector<dem::Vec3> forces = f.readVec3("force");
            if (ids.size() != forces.size())
            {
                failure = file + ": " + std::to_string(ids.size()) + " ids but "
                    + std::to_string(forces.size()) + " forces";
            }
            for (std::size_t k = 0; k < ids.size() && failure.empty(); ++k)
            {
                const double record[4] = {double(ids[k]), forces[k].x(), forces[k].y(), forces[k].z()};
                const char* bytes = reinterpret_cast<const char*>(record);
                all.insert(all.end(), bytes, bytes + sizeof record);
            }
        }
        catch (const std::exception& e)
        {
            failure = e.what();
        }
    }
    if (comm.anyTrue(!failure.empty()))
    {
        FatalErrorInFunction
            << "Reading the particle forces " << file.c_str() << " failed"
            << (failure.empty() ? std::string(" on rank 0") : ": " + failure).c_str()
            << exit(FatalError);
    }
    if (!comm.anyTrue(present))
    {
        return;  // computed from the air instead
    }
    const auto received = comm.exchange(std::vector<std::vector<char>>(comm.size(), comm.rank() == 0 ? all : std::vector<char>()));
    std::vector<double> d(received[0].size()/sizeof(double));
    if (!d.empty()) std::memcpy(d.data(), received[0].data(), received[0].size());
    std::unordered_map<std::int64_t, vector> byId;
    for (std::size_t k = 0; k + 3 < d.size(); k += 4)
    {
        byId[std::int64_t(d[k])] = vector(d[k + 1], d[k + 2], d[k + 3]);
    }
    auto& particles = runner_->simulation().particles();
    label missing = 0;
    for (label i = 0; i < nOwned(); ++i)
    {
        const auto it = byId.find(particles.id[i]);
        if (it == byId.end())
        {
            ++missing;
            continue;
        }
        particles.externalForce[i] = dem::Vec3(it->second.x(), it->second.y(), it->second.z());
    }
    reduce(missing, sumOp<label>());
    if (missing || label(byId.size()) != nParticles())
    {
        FatalErrorInFunction
            << file.c_str() << " holds the forces of " << byId.size()
            << " particles, the DEM restart file " << nParticles() << " ("
            << missing << " without a force)" << exit(FatalError);
    }
    restartForces_ = true;
    restartForcesFile_ = file;
}


double Foam::diefill::demCoupling::communicatorSeconds() const
{
    const auto* decomposition = runner_->simulation().decomposition();
    return decomposition ? decomposition->communicator().counters().seconds : 0.0;
}


void Foam::diefill::demCoupling::evolve()
{
    demStepsPerFluidStep();
    // The coupling's own exchanges go through the same communicator: only
    // the time inside the DEM's steps counts here
    const double before = communicatorSeconds();
    try
    {
        sigFpe::ignore noTrapping;
        runner_->advanceTo(mesh_.time().value());
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "The DEM failed:" << nl << "    " << e.what()
            << exit(FatalError);
    }
    demExchangeSeconds_ += communicatorSeconds() - before;
}


void Foam::diefill::demCoupling::updateVoidFraction()
{
    const clockValue started(true);
    const auto& particles = runner_->simulation().particles();
    const label owned = nOwned();

    // The particles spread over this rank's cells: all of them serially;
    // decomposed, the visitors routed here by their owners.
    std::vector<point> centres;
    std::vector<scalar> radii;
    for (label i = 0; i < owned; ++i)
    {
        const auto& x = particles.position[i];
        centres.emplace_back(x.x(), x.y(), x.z());
        radii.push_back(particles.radius[i]);
    }
    if (decomposed_)
    {
        routing_->route(centres, radii);
        centres.resize(routing_->nVisitors());
        radii.resize(routing_->nVisitors());
        for (label v = 0; v < routing_->nVisitors(); ++v)
        {
            centres[v] = routing_->visitorCentre(v);
            radii[v] = routing_->visitorRadius(v);
        }
    }
    const label n = label(centres.size());

    cells_.setSize(n);
    weights_.setSize(n);

    scalarField found(n, Zero);
    // demLib keeps particles sorted by position: the previous particle's cell
    // is a good first guess for the next one (the octree search it spares was
    // a tenth of the serial time of the full die-filling run)
    label hint = -1;
    for (label i = 0; i < n; ++i)
    {
        cells_[i].clear();
        weights_[i].clear();
        voidFraction_->distribute(centres[i], radii[i], hint, cells_[i], weights_[i]);
        found[i] = sum(weights_[i]);
    }

    // Normalise over all ranks: a particle partly outside the mesh (in a
    // wall) keeps its whole volume inside.
    std::vector<double> ownerTotal;  // decomposed: per particle this rank steps
    if (decomposed_)
    {
        ownerTotal = routing_->sumToOwners(std::vector<double>(found.begin(), found.end()), 1);
        const std::vector<double> back = routing_->sendToVisitors(ownerTotal, 1);
        forAll(found, v)
        {
            found[v] = back[v];
        }
    }
    else
    {
        Pstream::listCombineGather(found, plusEqOp<scalar>());
        Pstream::listCombineScatter(found);
    }

    scalarField solidFraction(mesh_.nCells(), Zero);
    scalar particleVolume = 0;
    nLost_ = 0;
    for (label i = 0; i < n; ++i)
    {
        if (found[i] <= 0)
        {
            // Counted by the owner (a visitor may hold none of its cells here)
            if (!decomposed_) ++nLost_;
            continue;
        }
        const scalar Vp = 4.0/3.0*constant::mathematical::pi*pow3(radii[i]);
        if (!decomposed_) particleVolume += Vp;
        forAll(cells_[i], k)
        {
            weights_[i][k] /= found[i];
            solidFraction[cells_[i][k]] += weights_[i][k]*Vp;
        }
    }
    solidFraction /= mesh_.V();

    if (smoothingLength_ > 0)
    {
        // Conservative: (1 - L^2 laplacian) s = s0 with zero-flux boundaries
        volScalarField s
        (
            IOobject("solidFraction", mesh_.time().timeName(), mesh_),
            mesh_,
            dimensionedScalar(dimless, Zero),
            zeroGradientFvPatchScalarField::typeName
        );
        s.primitiveFieldRef() = solidFraction;
        s.correctBoundaryConditions();
        const dimensionedScalar L2("L2", dimArea, sqr(smoothingLength_));
        fvScalarMatrix sEqn(fvm::Sp(dimensionedScalar("one", dimless, 1.0), s) - fvm::laplacian(L2, s));
        sEqn.source() += solidFraction*mesh_.V();
        dictionary solverDict;
        solverDict.add("solver", "PCG");
        solverDict.add("preconditioner", "DIC");
        solverDict.add("tolerance", 1e-12);
        solverDict.add("relTol", 0);
        sEqn.solve(solverDict);
        solidFraction = s.primitiveField();
    }

    scalarField& alpha = alpha_.primitiveFieldRef();
    label nClamped = 0;
    forAll(alpha, celli)
    {
        alpha[celli] = 1 - solidFraction[celli];
        if (alpha[celli] < alphaMin_)
        {
            alpha[celli] = alphaMin_;
            ++nClamped;
        }
    }
    alpha_.correctBoundaryConditions();

    if (decomposed_)
    {
        // The owners count their particles found in no cell of any rank
        for (label i = 0; i < owned; ++i)
        {
            if (ownerTotal[i] <= 0) ++nLost_;
            else particleVolume += 4.0/3.0*constant::mathematical::pi*pow3(particles.radius[i]);
        }
    }

    // The log line, with the volume conservation check (what the cells hold
    // vs the particles); decomposed, its figures in one reduction
    const scalarField& V = mesh_.V();
    FixedList<scalar, 8> figures
    ({
        scalar(nOwned()),
        scalar(nLost_),
        particleVolume,
        sum(solidFraction*V),
        sum(alpha*V),
        sum(V),
        scalar(nClamped),
        min(alpha)
    });
    if (decomposed_)
    {
        reduce(figures, sumThenMinOp<8, 1>());
        nLost_ = label(figures[1]);
    }

    Info<< "Coupling: " << label(figures[0]) << " particles (" << nLost_
        << " outside the mesh), solid volume: particles " << figures[2]
        << " m3, cells " << figures[3] << " m3; void fraction min "
        << figures[7] << " mean " << figures[4]/figures[5]
        << ", " << label(figures[6]) << " cell(s) clamped to alphaMin ("
        << double(started.elapsed()) << " s)" << endl;
}


void Foam::diefill::demCoupling::updateExchange
(
    volScalarField& Ksp,
    volVectorField& KUp
)
{
    const label n = nOwned();

    const auto [Uf, alphaP] =
        averageToParticles(U_.primitiveField(), alpha_.primitiveField());

    K_.setSize(n);
    scalarField& KspIn = Ksp.primitiveFieldRef();
    vectorField& KUpIn = KUp.primitiveFieldRef();
    KspIn = Zero;
    KUpIn = Zero;

    // K_i and v_i of every particle this rank steps; serially they go to its
    // cells at once, decomposed to the ranks it visits (below)
    std::vector<double> coefficients;
    for (label i = 0; i < n; ++i)
    {
        K_[i] = 0;
        vector velocity(Zero);
        if (alphaP[i] > 0)  // else outside the mesh
        {
            const particleFluidState s(state(i, Uf[i], alphaP[i], Zero));
            for (const particleForce& f : forces_)
            {
                K_[i] += f.implicitCoeff(s);
            }
            velocity = s.particleVelocity;
        }
        if (decomposed_)
        {
            coefficients.insert(coefficients.end(), {K_[i], velocity.x(), velocity.y(), velocity.z()});
            continue;
        }
        forAll(cells_[i], k)
        {
            const label celli = cells_[i][k];
            KspIn[celli] += weights_[i][k]*K_[i];
            KUpIn[celli] += weights_[i][k]*K_[i]*velocity;
        }
    }
    if (decomposed_)
    {
        const std::vector<double> visiting = routing_->sendToVisitors(coefficients, 4);
        forAll(cells_, v)
        {
            const scalar K = visiting[4*v];
            const vector velocity(visiting[4*v + 1], visiting[4*v + 2], visiting[4*v + 3]);
            forAll(cells_[v], k)
            {
                const label celli = cells_[v][k];
                KspIn[celli] += weights_[v][k]*K;
                KUpIn[celli] += weights_[v][k]*K*velocity;
            }
        }
    }

    // Per unit volume and air density (kinematic momentum equation)
    KspIn /= rho_*mesh_.V();
    KUpIn /= rho_*mesh_.V();
    Ksp.correctBoundaryConditions();
    KUp.correctBoundaryConditions();
}


void Foam::diefill::demCoupling::updateParticleForces
(
    const volScalarField& Ksp,
    const volVectorField& KUp
)
{
    auto& particles = runner_->simulation().particles();
    const label n = nOwned();

    const volVectorField gradP(rho_*fvc::grad(p_));
    const auto [Uf, alphaP, gradPP] = averageToParticles
    (
        U_.primitiveField(),
        alpha_.primitiveField(),
        gradP.primitiveField()
    );

    vector dragOnParticles(Zero);
    vector explicitOnParticles(Zero);
    vector meanVelocity(Zero);

    for (label i = 0; i < n; ++i)
    {
        vector F(Zero);
        if (alphaP[i] > 0)
        {
            const particleFluidState s(state(i, Uf[i], alphaP[i], gradPP[i]));
            const vector drag = K_[i]*s.slipVelocity();
            vector other(Zero);
            for (const particleForce& f : forces_)
            {
                other += f.explicitForce(s);
            }
            dragOnParticles += drag;
            explicitOnParticles += other;
            F = drag + other;
        }
        particles.externalForce[i] = dem::Vec3(F.x(), F.y(), F.z());
        const auto& v = particles.velocity[i];
        meanVelocity += vector(v.x(), v.y(), v.z());
    }
    // What the air lost through its exchange terms, from the fields alone
    const vector lostInCells =
        sum(mesh_.V()*(Ksp.primitiveField()*U_.primitiveField() - KUp.primitiveField()));

    // Decomposed: the log lines' sums in one reduction
    FixedList<scalar, 13> figures;
    for (direction c = 0; c < vector::nComponents; ++c)
    {
        figures[c] = dragOnParticles[c];
        figures[3 + c] = explicitOnParticles[c];
        figures[6 + c] = meanVelocity[c];
        figures[9 + c] = lostInCells[c];
    }
    figures[12] = n;
    if (decomposed_)
    {
        reduce(figures, sumThenMinOp<13, 0>());
        for (direction c = 0; c < vector::nComponents; ++c)
        {
            dragOnParticles[c] = figures[c];
            explicitOnParticles[c] = figures[3 + c];
            meanVelocity[c] = figures[6 + c];
        }
    }
    const label total = label(figures[12]);
    if (total > 0)
    {
        meanVelocity /= total;
    }
    const vector lostByAir(rho_*vector(figures[9], figures[10], figures[11]));

    Info<< "Coupling: drag on particles " << dragOnParticles
        << " N, momentum lost by the air " << lostByAir
        << " N, imbalance "
        << mag(dragOnParticles - lostByAir)/max(mag(dragOnParticles), VSMALL)
        << nl
        << "Coupling: other fluid forces on particles " << explicitOnParticles
        << " N, mean particle velocity " << meanVelocity << " m/s" << endl;
}


void Foam::diefill::demCoupling::write() const
{
    const auto& particles = runner_->simulation().particles();
    const IOobject header
    (
        "particleForces",
        mesh_.time().timeName(),
        "uniform",
        mesh_,
        IOobject::NO_READ,
        IOobject::NO_WRITE
    );
    if (decomposed_)
    {
        writeForcesById();
        return;
    }
    vectorIOField forces(header, nOwned());
    forAll(forces, i)
    {
        const auto& f = particles.externalForce[i];
        forces[i] = vector(f.x(), f.y(), f.z());
    }
    forces.write();
}


void Foam::diefill::demCoupling::finish()
{
    sigFpe::ignore noTrapping;
    runner_->finish();
}
