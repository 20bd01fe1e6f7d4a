// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {IInformationMarket} from "../IInformationMarket.sol";
import {MarketStorage} from "./MarketStorage.sol";

/// @title MarketWeights
/// @notice How each payment scheme weighs a record (docs/model.md §5): Outlier counts the similar records
/// of the same site, OutlierDistinct the distinct sellers with one, per record of its seller,
/// OutlierCapped voids a seller's records beyond the cap and weighs the rest as Outlier does (Delayed
/// weighs nothing: every record counts one). Also the exact similarity test they share.
/// @dev The schemes share one weighing loop over the live records loaded once into memory: apart, each
/// would load them again. Everything here is integer arithmetic on vectors below 2^47.
abstract contract MarketWeights is MarketStorage {
    /// @inheritdoc IInformationMarket
    function similar(int64 ax, int64 ay, int64 bx, int64 by) external view returns (bool) {
        (ax, ay) = _sellerVector(ax, ay, 0, 0);
        (bx, by) = _sellerVector(bx, by, 0, 0);
        return _similar(ax, ay, _norm2(ax, ay), bx, by, _norm2(bx, by), _cosTheta);
    }

    /// @dev The seller's rotated vector (docs/model.md §4: purchased vector minus seller position),
    /// range-checked, a zero vector replaced by (1, 0).
    function _sellerVector(int64 x, int64 y, int64 sx, int64 sy) internal pure returns (int64, int64) {
        int256 dx = int256(x) - sx;
        int256 dy = int256(y) - sy;
        if (dx >= _MAX_COMPONENT || dx <= -_MAX_COMPONENT || dy >= _MAX_COMPONENT || dy <= -_MAX_COMPONENT) {
            revert InfoMarketVectorOutOfRange(dx, dy);
        }
        return _nonZero(int64(dx), int64(dy));
    }

    function _nonZero(int64 x, int64 y) internal pure returns (int64, int64) {
        return x == 0 && y == 0 ? (int64(1), int64(0)) : (x, y);
    }

    /// @dev Weights of records [from, to) of `robot` against the live ones [live, end) of the same site.
    /// Outlier: the number of records (itself included) whose vector lies strictly within theta of its
    /// own. OutlierDistinct: the number of distinct sellers with such a record (its own seller once),
    /// times 1e27, divided by its seller's live records for the same site. OutlierCapped: a record
    /// preceded by `cap` live records of its seller is void (weight 0, and compared with nothing); the
    /// others weigh as under Outlier, among the counted records only. Loads the live records once into
    /// memory (one storage slot each): O(end - live) storage reads and O((to - from) * (end - live))
    /// comparisons, bounded by the caller's batch. Returns the weights' sum and, under OutlierCapped, how
    /// many live records count.
    function _weigh(address robot, uint64 live, uint64 from, uint64 to, uint64 end)
        internal
        returns (uint256 sum, uint256 counted)
    {
        uint256 m = end - live;
        int256[] memory xs = new int256[](m);
        int256[] memory ys = new int256[](m);
        uint256[] memory norms = new uint256[](m);
        uint256[] memory sites = new uint256[](m);
        // Distinct scheme: each record's seller as a small number (its rank among the live records'
        // sellers, from the chain of previous-record gaps), and each rank's number of live records.
        bool distinct = _scheme == Scheme.OutlierDistinct;
        uint256[] memory rank = new uint256[](distinct ? m : 0);
        uint256[] memory sales = new uint256[](distinct ? 2 * m : 0);
        uint256[] memory mark = new uint256[](distinct ? m : 0);
        uint256 ranks;
        // Capped scheme: each record's place among its seller's live records (0 for the first), from the
        // same chain of gaps; from place `cap` on a record is void.
        bool capped = _scheme == Scheme.OutlierCapped;
        uint256[] memory place = new uint256[](capped ? m : 0);
        mapping(uint256 => Information) storage records = _records[robot];
        for (uint256 k; k < m; ++k) {
            Information storage r = records[live + k];
            (xs[k], ys[k], sites[k]) = (r.dx, r.dy, r.site);
            norms[k] = _norm2(r.dx, r.dy);
            if (distinct) {
                uint256 gap = r.prevGap;
                uint256 q = gap != 0 && gap <= k ? rank[k - gap] : ranks++;
                rank[k] = q;
                ++sales[2 * q + r.site];
            } else if (capped) {
                uint256 gap = r.prevGap;
                uint256 p = gap != 0 && gap <= k ? place[k - gap] + 1 : 0;
                place[k] = p;
                if (p >= _cap) sites[k] = _VOID;
                else ++counted;
            }
        }
        int256 cosTheta = _cosTheta;
        for (uint256 i = from - live; i < to - live; ++i) {
            uint256 w = 1;
            (int256 x, int256 y, uint256 n, uint256 site) = (xs[i], ys[i], norms[i], sites[i]);
            if (distinct) {
                mark[rank[i]] = i + 1; // its own seller counts once, by this record
                for (uint256 j; j < m; ++j) {
                    if (sites[j] != site || mark[rank[j]] == i + 1) continue;
                    if (_similar(x, y, n, xs[j], ys[j], norms[j], cosTheta)) {
                        mark[rank[j]] = i + 1;
                        unchecked {
                            ++w;
                        }
                    }
                }
                w = (w * _DISTINCT_SCALE) / sales[2 * rank[i] + site];
            } else if (site == _VOID) {
                w = 0;
            } else {
                for (uint256 j; j < m; ++j) {
                    if (j == i || sites[j] != site) continue;
                    if (_similar(x, y, n, xs[j], ys[j], norms[j], cosTheta)) {
                        unchecked {
                            ++w;
                        }
                    }
                }
            }
            records[live + i].weight = uint104(w);
            sum += w;
        }
    }

    /// @dev OutlierCapped: what a live record of count `count` (0: void) is paid of `liveAmount`, and its
    /// weight. A void record weighs its stake, the counted ones share the rest (the share and their own
    /// stakes) by their counts, C their sum: weights stake * C and (share + counted * stake) * count over
    /// C * (share + m * stake) for m live records, as the simulated ledger pays them.
    function _cappedShare(Settlement storage s, uint256 count, uint256 liveAmount, uint256 m)
        internal
        view
        returns (uint256 weight, uint256 share)
    {
        uint256 shared = (_reward * _informationShare) / _WAD;
        uint256 sum = s.totalWeight;
        weight = count == 0 ? _stake * sum : (shared + s.counted * _stake) * count;
        uint256 total = sum * (shared + m * _stake);
        share = total == 0 ? 0 : (liveAmount * weight) / total;
    }

    function _norm2(int256 x, int256 y) internal pure returns (uint256) {
        unchecked {
            return uint256(x * x + y * y); // below 2^95: components are below 2^47
        }
    }

    /// @dev angle(a, b) < theta  <=>  a.b > cos(theta) |a| |b|, decided without square roots:
    /// with c = cos(theta) * S (S = 1e9) and d = a.b,
    /// - c >= 0: similar iff d > 0 and d^2 S^2 > c^2 |a|^2 |b|^2;
    /// - c < 0: similar iff d >= 0 or d^2 S^2 < c^2 |a|^2 |b|^2.
    /// Components are below 2^47, so every product is below 2^250: exact integer arithmetic.
    function _similar(int256 ax, int256 ay, uint256 na, int256 bx, int256 by, uint256 nb, int256 c)
        internal
        pure
        returns (bool)
    {
        unchecked {
            int256 d = ax * bx + ay * by;
            uint256 lhs = uint256(d * d) * uint256(_COS_SCALE * _COS_SCALE);
            uint256 rhs = uint256(c * c) * na * nb;
            if (c >= 0) return d > 0 && lhs > rhs;
            return d >= 0 || lhs < rhs;
        }
    }
}
