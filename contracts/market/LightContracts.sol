// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {IInformationMarket} from "../IInformationMarket.sol";
import {MarketEIP712} from "./MarketEIP712.sol";
import {MarketRoles} from "./MarketRoles.sol";
import {MarketWeights} from "./MarketWeights.sol";

/// @title LightContracts
/// @notice The seller's side: a light contract (an offer the buyer signed off-chain) executed by its
/// seller, which records the sale under the buyer's open round trip, reveals the path information and
/// locks the seller's stake; and the views of a buyer's open round trip.
/// @dev Every check of a reveal has its own error (docs/chain.md); `_countSale` keeps the per-seller and
/// per-trip bounds that keep every later settlement's work bounded.
abstract contract LightContracts is MarketRoles, MarketEIP712, MarketWeights {
    /// @inheritdoc IInformationMarket
    function revealInformation(LightContract calldata lc, PathInfo calldata info) external {
        _requireNotPaused();
        Offer calldata offer = lc.offer;
        address seller = offer.seller;
        address buyer = lc.buyer;
        if (msg.sender != seller) revert InfoMarketUnauthorizedSeller(msg.sender, seller);
        if (block.number > offer.maxBlock) revert InfoMarketExpiredContract(offer.maxBlock, block.number);
        if (offer.maxBlock > block.number + _maxValidity) {
            revert InfoMarketValidityTooLong(offer.maxBlock, block.number + _maxValidity);
        }
        if (buyer == seller) revert InfoMarketSelfDealing(seller);
        if (offer.site > 1) revert InfoMarketInvalidSite(offer.site);
        if (!_registered[seller]) revert InfoMarketUnregistered(seller);
        if (!_registered[buyer]) revert InfoMarketUnregistered(buyer);

        _checkBuyerSignature(lc);
        Round storage round = _rounds[buyer];
        if (lc.trip != round.trip) revert InfoMarketWrongTrip(buyer, lc.trip, round.trip);

        bytes32 key = revealKey(offer.site, offer.age, offer.maxBlock, buyer, seller, offer.pathHash);
        if (_revealed[key]) revert InfoMarketAlreadyRevealed(key);
        _revealed[key] = true;

        bytes32 revealed = keccak256(abi.encode(info.x, info.y, info.salt));
        if (revealed != offer.pathHash) revert InfoMarketInformationMismatch(offer.pathHash, revealed);

        (int64 dx, int64 dy) = _sellerVector(info.x, info.y, lc.sellerX, lc.sellerY);
        uint64 index = round.count;
        if (index - round.start >= _maxRecordsPerTrip) revert InfoMarketTripFull(buyer, _maxRecordsPerTrip);
        uint16 prevGap = _countSale(buyer, seller, index);

        uint256 stake_ = _stake;
        if (stake_ > 0) {
            uint256 balance = _balances[seller];
            if (balance < stake_) revert InfoMarketInsufficientStake(seller, balance, stake_);
            _balances[seller] = balance - stake_;
            _pots[buyer] += stake_;
            emit StakeLocked(seller, buyer, stake_);
        }

        _records[buyer][index] = Information(seller, uint64(block.number), offer.site, dx, dy, 0, prevGap);
        round.count = index + 1;
        emit InformationRevealed(
            buyer, seller, key, index, offer.site, offer.age, info.x, info.y, lc.sellerX, lc.sellerY, offer.pathHash
        );
    }

    /// @inheritdoc IInformationMarket
    function revealKey(uint8 site, uint32 age, uint64 maxBlock, address buyer, address seller, bytes32 pathHash)
        public
        pure
        returns (bytes32)
    {
        return keccak256(abi.encode(site, age, maxBlock, buyer, seller, pathHash));
    }

    /// @inheritdoc IInformationMarket
    function isRevealed(bytes32 key) external view returns (bool) {
        return _revealed[key];
    }

    /// @inheritdoc IInformationMarket
    function contributors(address buyer) external view returns (Information[] memory list) {
        Round storage round = _rounds[buyer];
        uint256 start = round.start;
        list = new Information[](round.count - start);
        for (uint256 i; i < list.length; ++i) list[i] = _records[buyer][start + i];
    }

    /// @inheritdoc IInformationMarket
    function roundTrip(address buyer) external view returns (uint64) {
        return _rounds[buyer].trip;
    }

    function _checkBuyerSignature(LightContract calldata lc) internal view {
        bytes32 digest = acceptanceDigest(lc.offer, lc.buyer, lc.sellerX, lc.sellerY, lc.trip);
        address recovered = _recover(digest, lc.v, lc.r, lc.s);
        if (recovered == address(0) || recovered != lc.buyer) revert InfoMarketInvalidBuyerSignature(lc.buyer, recovered);
    }

    /// @dev Counts a sale of `seller` to `buyer` in the buyer's open round trip, within the bound, as
    /// record `index`; returns how far back the seller's previous record of the round trip lies (0 when
    /// none, or when it is too far back to be live: a live window is at most 512 records).
    /// A seller's further record (not its first in the round trip) is refused when it would take more
    /// than half of the room the first records leave, so that colluders cannot fill a round trip with
    /// repeated sales: a seller not yet heard is refused only when at least half of `maxRecordsPerTrip`
    /// distinct sellers sold in it.
    function _countSale(address buyer, address seller, uint64 index) internal returns (uint16 prevGap) {
        Round storage round = _rounds[buyer];
        uint256 trip = round.trip;
        uint256 packed = _sold[buyer][seller];
        bool same = packed >> 128 == trip + 1;
        uint256 n = same ? packed & type(uint64).max : 0;
        if (n >= _maxRecordsPerSeller) revert InfoMarketTooManyRecords(buyer, seller, _maxRecordsPerSeller);
        if (same) {
            uint256 gap = index - ((packed >> 64) & type(uint64).max);
            if (gap <= _MAX_TRIP_RECORDS) prevGap = uint16(gap);
            uint256 rp = _repeats[buyer];
            uint256 repeats = rp >> 64 == trip + 1 ? rp & type(uint64).max : 0;
            uint256 firsts = index - round.first - repeats;
            if (2 * (repeats + 1) + firsts > _maxRecordsPerTrip) revert InfoMarketTripReserved(buyer, seller, repeats);
            _repeats[buyer] = ((trip + 1) << 64) | (repeats + 1);
        }
        _sold[buyer][seller] = ((trip + 1) << 128) | (uint256(index) << 64) | (n + 1);
    }
}
