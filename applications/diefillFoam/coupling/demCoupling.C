#include "demCoupling.H"
#include "dragForce.H"
#include "checkKeywords.H"
#include "fvm.H"
#include "fvc.H"
#include "mathematicalConstants.H"
#include "sigFpe.H"
#include "vectorIOField.H"
#include "clockValue.H"

#include "demLib/case_lock.hpp"
#include "demLib/case_runner.hpp"
#include "demLib/case_setup.hpp"
#include "demLib/error.hpp"
#include "demLib/version.hpp"

#include <cmath>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <sstream>

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
Foam::Field<Type> Foam::diefill::demCoupling::averageToParticles
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
    // Master sums and sends back: every rank gets the same bits.
    Pstream::listCombineGather(result, plusEqOp<Type>());
    Pstream::listCombineScatter(result);
    return result;
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

    // Each rank runs the same DEM; only the master's output goes to the case
    // output folder, the others write theirs below their processor folder.
    if (Pstream::parRun() && !Pstream::master())
    {
        setup.output.directory =
            "processor" + std::to_string(Pstream::myProcNo()) + "/"
          + setup.output.directory;
    }

    dem::RunOptions options;
    options.progressInterval = 0;
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
        if (forcesHeader.typeHeaderOk<vectorIOField>(true))
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

Foam::label Foam::diefill::demCoupling::nParticles() const
{
    return runner_->simulation().particles().size();
}


void Foam::diefill::demCoupling::evolve()
{
    demStepsPerFluidStep();
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
}


void Foam::diefill::demCoupling::updateVoidFraction()
{
    const clockValue started(true);
    const auto& particles = runner_->simulation().particles();
    const label n = particles.size();

    cells_.setSize(n);
    weights_.setSize(n);

    scalarField found(n, Zero);
    // demLib keeps particles sorted by position: the previous particle's cell
    // is a good first guess for the next one (the octree search it spares was
    // a tenth of the serial time of the full die-filling run)
    label hint = -1;
    for (label i = 0; i < n; ++i)
    {
        const auto& x = particles.position[i];
        cells_[i].clear();
        weights_[i].clear();
        voidFraction_->distribute
        (
            point(x.x(), x.y(), x.z()),
            particles.radius[i],
            hint,
            cells_[i],
            weights_[i]
        );
        found[i] = sum(weights_[i]);
    }

    // Normalise over all ranks: a particle partly outside the mesh (in a
    // wall) keeps its whole volume inside.
    Pstream::listCombineGather(found, plusEqOp<scalar>());
    Pstream::listCombineScatter(found);

    scalarField solidFraction(mesh_.nCells(), Zero);
    scalar particleVolume = 0;
    nLost_ = 0;
    for (label i = 0; i < n; ++i)
    {
        if (found[i] <= 0)
        {
            ++nLost_;
            continue;
        }
        const scalar Vp =
            4.0/3.0*constant::mathematical::pi*pow3(particles.radius[i]);
        particleVolume += Vp;
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

    // Volume conservation check: what the cells hold vs the particles
    const scalar cellVolume = gSum(solidFraction*mesh_.V());
    reduce(nClamped, sumOp<label>());

    Info<< "Coupling: " << n << " particles (" << nLost_
        << " outside the mesh), solid volume: particles " << particleVolume
        << " m3, cells " << cellVolume << " m3; void fraction min "
        << gMin(alpha) << " mean " << gSum(alpha*mesh_.V())/gSum(mesh_.V())
        << ", " << nClamped << " cell(s) clamped to alphaMin ("
        << double(started.elapsed()) << " s)" << endl;
}


void Foam::diefill::demCoupling::updateExchange
(
    volScalarField& Ksp,
    volVectorField& KUp
)
{
    const auto& particles = runner_->simulation().particles();
    const label n = particles.size();

    const vectorField Uf(averageToParticles<vector>(U_.primitiveField()));
    const scalarField alphaP(averageToParticles<scalar>(alpha_.primitiveField()));

    K_.setSize(n);
    scalarField& KspIn = Ksp.primitiveFieldRef();
    vectorField& KUpIn = KUp.primitiveFieldRef();
    KspIn = Zero;
    KUpIn = Zero;

    for (label i = 0; i < n; ++i)
    {
        K_[i] = 0;
        if (alphaP[i] <= 0)
        {
            continue;  // outside the mesh
        }
        const particleFluidState s(state(i, Uf[i], alphaP[i], Zero));
        for (const particleForce& f : forces_)
        {
            K_[i] += f.implicitCoeff(s);
        }
        forAll(cells_[i], k)
        {
            const label celli = cells_[i][k];
            KspIn[celli] += weights_[i][k]*K_[i];
            KUpIn[celli] += weights_[i][k]*K_[i]*s.particleVelocity;
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
    const label n = particles.size();

    const vectorField Uf(averageToParticles<vector>(U_.primitiveField()));
    const scalarField alphaP(averageToParticles<scalar>(alpha_.primitiveField()));
    const volVectorField gradP(rho_*fvc::grad(p_));
    const vectorField gradPP(averageToParticles<vector>(gradP.primitiveField()));

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
    if (n > 0)
    {
        meanVelocity /= n;
    }

    // What the air lost through its exchange terms, from the fields alone
    const vector lostByAir =
        rho_*gSum(mesh_.V()*(Ksp.primitiveField()*U_.primitiveField()
      - KUp.primitiveField()));

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
    vectorIOField forces
    (
        IOobject
        (
            "particleForces",
            mesh_.time().timeName(),
            "uniform",
            mesh_,
            IOobject::NO_READ,
            IOobject::NO_WRITE
        ),
        label(particles.size())
    );
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
