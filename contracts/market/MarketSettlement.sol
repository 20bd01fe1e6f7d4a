// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {IInformationMarket} from "../IInformationMarket.sol";
import {MarketEIP712} from "./MarketEIP712.sol";
import {MarketRoles} from "./MarketRoles.sol";
import {MarketWeights} from "./MarketWeights.sol";

/// @title MarketSettlement
/// @notice Records and settlement: a deposit (or a round trip's expiry) closes the buyer's round trip
/// into a settlement that weighs every record by the scheme ({MarketWeights}) and pays each its part of
/// the reward's share and the stakes, in calls of bounded work, a bounty paying whoever does the work;
/// and the token ledger's views.
/// @dev A settlement runs phase by phase (closed, weighing, paying) and stops wherever its budget ends;
/// `settle` continues it. Delayed pays by count, OutlierCapped by `_cappedShare`, the others by weight.
abstract contract MarketSettlement is MarketRoles, MarketEIP712, MarketWeights {
    /// @inheritdoc IInformationMarket
    function buyItem(address robot, DepositEvidence calldata evidence) external returns (bool done) {
        _requireRole(DEPOSITOR_ROLE);
        _requireNotPaused();
        if (!_registered[robot]) revert InfoMarketUnregistered(robot);
        Settlement storage s = _settlements[robot];
        if (s.end != 0) revert InfoMarketSettlementPending(robot, s.end - s.next);
        Round storage round = _rounds[robot];
        bytes32 digest = depositDigest(robot, round.trip);
        address signer = _recover(digest, evidence.robotV, evidence.robotR, evidence.robotS);
        if (signer == address(0) || signer != robot) revert InfoMarketInvalidDepositSignature(robot, signer);
        signer = _recover(digest, evidence.nestV, evidence.nestR, evidence.nestS);
        if (signer == address(0) || !_roles[NEST_ROLE][signer]) revert InfoMarketUnacknowledgedDeposit(robot, signer);
        uint256 share = (_reward * _informationShare) / _WAD;
        // The robot receives the reward and escrows the share: never negative since share <= reward.
        _balances[robot] += _reward - share;
        _totalSupply += _reward;
        emit ItemBought(robot, _reward, _pots[robot], round.count - round.first);
        done = _close(robot, share, _settleBatch);
    }

    /// @inheritdoc IInformationMarket
    function settle(address robot, uint256 maxRecords) external returns (bool done) {
        if (_settlements[robot].end == 0) revert InfoMarketNothingToSettle(robot);
        return _settle(robot, maxRecords < _settleBatch ? maxRecords : _settleBatch);
    }

    /// @inheritdoc IInformationMarket
    function refundExpired(address buyer, uint256 maxRecords) external returns (uint256 refunded) {
        Round storage round = _rounds[buyer];
        uint64 first = round.first;
        uint64 end = round.count;
        if (end == first) return 0;
        if (_registered[buyer] && !_expired(_records[buyer][first].openedAt, block.number)) return 0;
        Settlement storage s = _settlements[buyer];
        if (s.end != 0) revert InfoMarketSettlementPending(buyer, s.end - s.next);
        uint256 share = (_reward * _informationShare) / _WAD;
        uint256 balance = _balances[buyer];
        if (share > balance) share = balance;
        _balances[buyer] = balance - share;
        emit RoundTripExpired(buyer, share, _pots[buyer], end - first);
        _close(buyer, share, maxRecords < _settleBatch ? maxRecords : _settleBatch);
        refunded = end - first;
    }

    /// @inheritdoc IInformationMarket
    function balanceOf(address robot) external view returns (uint256) {
        return _balances[robot];
    }

    /// @inheritdoc IInformationMarket
    function lockedStake(address buyer) external view returns (uint256) {
        return _pots[buyer] + _settlements[buyer].escrow;
    }

    /// @inheritdoc IInformationMarket
    function pendingSettlement(address robot) external view returns (bool pending, uint8 phase, uint256 remaining) {
        Settlement storage s = _settlements[robot];
        if (s.end == 0) return (false, 0, 0);
        return (true, s.phase, s.end - s.next);
    }

    /// @inheritdoc IInformationMarket
    function totalSupply() external view returns (uint256) {
        return _totalSupply;
    }

    /// @inheritdoc IInformationMarket
    function decimals() external pure returns (uint8) {
        return 9;
    }

    function _expired(uint64 openedAt, uint256 now_) internal view returns (bool) {
        return uint256(openedAt) + _stakeExpiry <= now_;
    }

    /// @dev Closes `robot`'s open round trip (by a deposit or by its expiry) into a settlement whose
    /// escrow holds `share` and the round trip's stakes, and runs it for `budget` units of work.
    function _close(address robot, uint256 share, uint256 budget) internal returns (bool) {
        Settlement storage s = _settlements[robot];
        Round storage round = _rounds[robot];
        uint256 pot = _pots[robot];
        _pots[robot] = 0;
        uint64 first = round.first;
        uint64 end = round.count;
        round.start = end;
        round.first = end;
        round.trip += 1;
        s.next = first;
        s.end = end;
        s.closedAt = uint64(block.number);
        s.live = first;
        s.phase = _CLOSED_TRIP;
        s.first = first;
        s.escrow = share + pot;
        return _settle(robot, budget);
    }

    /// @dev Runs the pending settlement of `robot` for at most `budget` units of work, phase by phase:
    /// weigh the records, pay every record of the round trip by weight; then return the rest. However
    /// late it is finished, the records are weighed as a prompt settlement weighs them: a seller gains
    /// nothing by a settlement left pending.
    /// A registered caller, and from `settlementDeadline` blocks after the deposit any caller, earns
    /// `settleBounty` per unit: for weighing from the escrow before the paid amount is
    /// fixed, for paying from each record's share.
    function _settle(address robot, uint256 budget) internal returns (bool) {
        Settlement storage s = _settlements[robot];
        // Past the settlement deadline the bounty is paid to any caller, registered or not, so that an
        // outside keeper is paid to finish what the robots left.
        bool late = block.number >= uint256(s.closedAt) + _settlementDeadline;
        uint256 rate = _settleBounty != 0 && (_registered[msg.sender] || late) ? _settleBounty : 0;
        uint256 units = budget;
        uint64 next = s.next;
        uint64 end = s.end;
        uint256 escrow = s.escrow;
        uint8 phase = s.phase;
        if (phase == _CLOSED_TRIP) phase = _scheme == Scheme.Delayed ? _PAY : _WEIGH;
        if (phase == _WEIGH) {
            // Weighing one record compares it with every live record: it costs ceil(m / pairs per unit)
            // units of the budget, so a batch's gas stays bounded (m <= 512, docs/gas.md).
            uint256 per = _scheme == Scheme.OutlierDistinct ? _DISTINCT_PAIRS_PER_UNIT : _PAIRS_PER_UNIT;
            uint256 cost = (end - s.live + per - 1) / per;
            if (cost == 0) cost = 1; // no live record: nothing to weigh
            uint256 affordable = budget / cost;
            if (next < end && affordable == 0 && budget == _settleBatch) affordable = 1;
            if (next < end && affordable > 0) {
                uint64 stop = next + uint64(affordable < end - next ? affordable : end - next);
                (uint256 sum, uint256 counted) = _weigh(robot, s.live, next, stop, end);
                s.totalWeight += sum;
                if (_scheme == Scheme.OutlierCapped) s.counted = uint64(counted);
                uint256 spent = (stop - next) * cost;
                budget = spent < budget ? budget - spent : 0;
                next = stop;
            }
            if (next < end) {
                s.phase = _WEIGH;
                return _pause(robot, next, escrow, rate * (units - budget));
            }
            phase = _PAY;
        }
        uint256 bounty;
        uint64 first = s.first;
        uint64 live = s.live;
        if (phase != s.phase) {
            // Paying starts, from the round trip's first record: the work so far is paid from the
            // escrow (never more than it holds: an expired round trip's share may be short), then what
            // the records share is fixed.
            bounty = rate * (units - budget);
            if (bounty > escrow) bounty = escrow;
            escrow -= bounty;
            s.amount = escrow;
            if (_scheme == Scheme.Delayed) s.totalWeight = end - live;
            s.phase = phase;
            next = first;
        }
        uint256 amount = s.amount;
        uint256 total = s.totalWeight;
        bool equal = _scheme == Scheme.Delayed;
        bool capped = !equal && _scheme == Scheme.OutlierCapped;
        while (next < end && budget > 0) {
            Information storage record = _records[robot][next];
            uint256 weight = equal ? 1 : record.weight;
            uint256 share;
            if (capped) {
                (weight, share) = _cappedShare(s, weight, amount, end - live);
            } else {
                share = (amount * weight) / total;
            }
            uint256 cut = rate < share ? rate : share;
            _balances[record.seller] += share - cut;
            escrow -= share;
            bounty += cut;
            emit RewardShared(robot, record.seller, next, weight, share - cut);
            ++next;
            --budget;
        }
        _payBounty(robot, bounty);
        if (next < end) {
            s.next = next;
            s.escrow = escrow;
            return false;
        }
        return _finish(robot, escrow, first < end ? amount - escrow : 0, total);
    }

    /// @dev Stops a settlement call before paying: records where it stands and pays the bounty.
    function _pause(address robot, uint64 next, uint256 escrow, uint256 bounty) internal returns (bool) {
        Settlement storage s = _settlements[robot];
        if (bounty > escrow) bounty = escrow; // an expired round trip's share may be short
        s.next = next;
        s.escrow = escrow - bounty;
        _payBounty(robot, bounty);
        return false;
    }

    function _payBounty(address robot, uint256 bounty) internal {
        if (bounty == 0) return;
        _balances[msg.sender] += bounty;
        emit SettlementBountyPaid(msg.sender, robot, bounty);
    }

    /// @dev Ends a settlement: what the escrow still holds goes back to the robot.
    function _finish(address robot, uint256 kept, uint256 shared, uint256 total)
        internal
        returns (bool)
    {
        _balances[robot] += kept;
        emit SettlementCompleted(robot, shared, kept, total);
        delete _settlements[robot];
        // When nothing was revealed to the robot since its deposit, its next round trip can start
        // again at index 0 and rewrite warm slots (about 5k gas each) instead of fresh ones (22k). Not
        // when its open round trip holds records: their sellers' links (`_sold`) point at their indices.
        Round storage round = _rounds[robot];
        if (round.count == round.first) {
            round.start = 0;
            round.count = 0;
            round.first = 0;
        }
        return true;
    }
}
