#include "particleRouting.H"
#include "error.H"

#include <cstring>

namespace
{

void appendDoubles(std::vector<char>& out, const double* values, std::size_t n)
{
    const std::size_t at = out.size();
    out.resize(at + n*sizeof(double));
    if (n) std::memcpy(out.data() + at, values, n*sizeof(double));
}

std::vector<double> asDoubles(const std::vector<char>& in)
{
    std::vector<double> values(in.size()/sizeof(double));
    if (!values.empty()) std::memcpy(values.data(), in.data(), values.size()*sizeof(double));
    return values;
}

} // End anonymous namespace


Foam::diefill::particleRouting::particleRouting
(
    const dem::Communicator& comm,
    const treeBoundBox& localBounds
)
:
    comm_(comm),
    sent_(comm.size()),
    receivedFrom_(comm.size(), 0)
{
    // Every rank's box to every rank (6 numbers each)
    const double box[6] =
    {
        localBounds.min().x(), localBounds.min().y(), localBounds.min().z(),
        localBounds.max().x(), localBounds.max().y(), localBounds.max().z()
    };
    std::vector<char> mine;
    appendDoubles(mine, box, 6);
    const auto all = comm_.exchange(std::vector<std::vector<char>>(comm_.size(), mine));
    for (const auto& bytes : all)
    {
        const std::vector<double> b(asDoubles(bytes));
        if (b.size() != 6)
        {
            FatalErrorInFunction
                << "a rank sent " << b.size() << " numbers for its bounds, expected 6"
                << exit(FatalError);
        }
        bounds_.emplace_back(point(b[0], b[1], b[2]), point(b[3], b[4], b[5]));
    }
}


void Foam::diefill::particleRouting::route
(
    const std::vector<point>& centres,
    const std::vector<scalar>& radii
)
{
    const int ranks = comm_.size();
    nOwned_ = label(centres.size());
    std::vector<std::vector<char>> send(ranks);
    for (auto& list : sent_) list.clear();
    for (label i = 0; i < nOwned_; ++i)
    {
        const point& x = centres[i];
        const scalar r = radii[i];
        for (int rank = 0; rank < ranks; ++rank)
        {
            const treeBoundBox& b = bounds_[rank];
            // The sphere's box overlaps the subdomain's bounds (an empty
            // subdomain's inverted box overlaps nothing)
            if
            (
                x.x() + r < b.min().x() || x.x() - r > b.max().x()
             || x.y() + r < b.min().y() || x.y() - r > b.max().y()
             || x.z() + r < b.min().z() || x.z() - r > b.max().z()
            )
            {
                continue;
            }
            sent_[rank].push_back(i);
            const double data[4] = {x.x(), x.y(), x.z(), r};
            appendDoubles(send[rank], data, 4);
        }
    }
    const auto received = comm_.exchange(send);
    centres_.clear();
    radii_.clear();
    for (int rank = 0; rank < ranks; ++rank)
    {
        const std::vector<double> d(asDoubles(received[rank]));
        receivedFrom_[rank] = label(d.size()/4);
        for (std::size_t k = 0; k + 3 < d.size(); k += 4)
        {
            centres_.emplace_back(d[k], d[k + 1], d[k + 2]);
            radii_.push_back(d[k + 3]);
        }
    }
}


std::vector<double> Foam::diefill::particleRouting::sumToOwners
(
    const std::vector<double>& perVisitor,
    label width
) const
{
    const int ranks = comm_.size();
    std::vector<std::vector<char>> send(ranks);
    std::size_t v = 0;
    for (int rank = 0; rank < ranks; ++rank)
    {
        appendDoubles(send[rank], perVisitor.data() + v*width, std::size_t(receivedFrom_[rank])*width);
        v += receivedFrom_[rank];
    }
    // Each rank knows what comes back: its particles sent there (one round)
    std::vector<std::size_t> expected(ranks);
    for (int rank = 0; rank < ranks; ++rank)
    {
        expected[rank] = sent_[rank].size()*width*sizeof(double);
    }
    const auto received =
        comm_.exchangeKnownSizesAndAnyTrue(send, expected, false).received;
    std::vector<double> sum(std::size_t(nOwned_)*width, 0.0);
    for (int rank = 0; rank < ranks; ++rank)
    {
        const std::vector<double> d(asDoubles(received[rank]));
        if (d.size() != sent_[rank].size()*width)
        {
            FatalErrorInFunction
                << "rank " << rank << " returned " << d.size() << " values for "
                << sent_[rank].size() << " particles" << exit(FatalError);
        }
        for (std::size_t k = 0; k < sent_[rank].size(); ++k)
        {
            for (label c = 0; c < width; ++c)
            {
                sum[std::size_t(sent_[rank][k])*width + c] += d[k*width + c];
            }
        }
    }
    return sum;
}


std::vector<double> Foam::diefill::particleRouting::sendToVisitors
(
    const std::vector<double>& perOwned,
    label width
) const
{
    const int ranks = comm_.size();
    std::vector<std::vector<char>> send(ranks);
    for (int rank = 0; rank < ranks; ++rank)
    {
        for (const label i : sent_[rank])
        {
            appendDoubles(send[rank], perOwned.data() + std::size_t(i)*width, width);
        }
    }
    // Each rank knows what comes: its visitors from there (one round)
    std::vector<std::size_t> expected(ranks);
    for (int rank = 0; rank < ranks; ++rank)
    {
        expected[rank] = std::size_t(receivedFrom_[rank])*width*sizeof(double);
    }
    const auto received =
        comm_.exchangeKnownSizesAndAnyTrue(send, expected, false).received;
    std::vector<double> values;
    values.reserve(centres_.size()*width);
    for (int rank = 0; rank < ranks; ++rank)
    {
        const std::vector<double> d(asDoubles(received[rank]));
        if (d.size() != std::size_t(receivedFrom_[rank])*width)
        {
            FatalErrorInFunction
                << "rank " << rank << " sent " << d.size() << " values for "
                << receivedFrom_[rank] << " visitors" << exit(FatalError);
        }
        values.insert(values.end(), d.begin(), d.end());
    }
    return values;
}
