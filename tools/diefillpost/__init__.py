"""diefillpost: post-processing of diefill/demRun particle output without ParaView.

Modules (one concept each):
    foamdict   read constant/demProperties (OpenFOAM dictionary subset) into Python
    series     the HDF5 particle series written by demRun (dem/particles_*.h5)
    summary    dem/summary.csv
    geometry   rotations, wall poses from the motion blocks, named regions
    profile    bed surface profiles and fitted slope angles
    plate      mass on a tilting plate, slid fraction vs plate angle
    plots      PNG pictures (matplotlib, Agg)
    results    results.json + results.csv (write, or update: merged with what is there)
    closedmesh a closed STL surface (a die cavity): points inside, depth, volume per cell
    cavity     a die cavity placed at the table, split into opening, floors and walls; the table
    shoemotion a shoe's motion from a table of time and position (translation segments)
    output     output files that replace the old ones only once complete
    phasetimes diefillFoam's wall-time table (where the time loop went), for the bench and the tests
"""
__all__ = ["foamdict", "series", "summary", "geometry", "profile", "plate", "plots", "results", "output",
           "closedmesh", "cavity", "shoemotion", "phasetimes"]
