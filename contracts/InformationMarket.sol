// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {LightContracts} from "./market/LightContracts.sol";
import {MarketRegistration} from "./market/MarketRegistration.sol";
import {MarketRoles} from "./market/MarketRoles.sol";
import {MarketSettlement} from "./market/MarketSettlement.sol";
import {MarketStorage} from "./market/MarketStorage.sol";

/// @title InformationMarket
/// @notice On-chain half of the robot swarm's information market (docs/model.md §5 and §9): sellers
/// reveal path information under a light contract the buyer signed off-chain, and the market account
/// pays every deposited item and shares part of the reward among the robot's information sellers.
/// @dev Balances live in an internal ledger of this contract's own token (9 decimals), not in an
/// ERC-20: robots never transfer tokens to each other directly, every movement of money is one of the
/// market's rules (stake, reward, share), and leaving `transfer`/`approve` out keeps the only ways to
/// move money the ones this contract audits. Invariant: the sum of all balances plus all locked stakes
/// and bonds equals `totalSupply()` (initial wealth granted plus every reward issued, less the bonds
/// forfeited); stakes still locked in a buyer's pot or in a settlement count as locked. Rounding dust of a share stays with the depositing
/// robot, so no token is ever created or destroyed by a division.
///
/// The contract trusts no seller's word about its information: the direction each record is weighed
/// by is that of the vector the seller committed to, minus the seller's position the buyer signed
/// (docs/model.md §4), and "within theta" is decided on those integer vectors with dot products
/// against a fixed cos(theta), exactly. A stake never stays locked for ever: once the first record of a
/// round trip is `stakeExpiry` blocks old (never 0), anyone may settle the whole round trip
/// (`refundExpired`) as a prompt deposit would, every record weighed, the share paid out of the buyer's
/// balance as far as it goes (it gets the whole reward at its next deposit), so neither the buyer nor a
/// seller of many records gains anything by letting records expire; a deposit not weighed within
/// `settlementDeadline` blocks is still weighed, never paid by a cruder rule (so nobody gains by
/// leaving it unfinished), and from then on any caller earns the bounty for finishing it. Every call
/// does a bounded amount of work: a round trip holds at most
/// `maxRecordsPerTrip` (<= 512) live records, one seller at most `maxRecordsPerSeller` of them, and
/// `buyItem`, `settle` and `refundExpired` each do at most `settleBatch` (<= 48) units of work, so no
/// call exceeds the gas bound docs/gas.md declares, measured with cold storage, whatever the number of
/// records or sellers. A registered robot that settles someone's deposit earns `settleBounty` per unit
/// of work, taken from the share, so settling is worth doing for whoever does it.
///
/// Trust (docs/chain.md, "Trust model"): roles, as in OpenZeppelin's AccessControl. The admin grants
/// and revokes roles (key rotation; several accounts may hold a role). A robot is registered when
/// `registrarThreshold` distinct registrars approved the same (robot, grant), each approval standing
/// only while its key holds the registrar role and for `registrarPeriod` blocks (its registrar may
/// cancel it), and a registrar approves (registrations and revocations together) at most
/// `registrarQuota` times in any `registrarPeriod` consecutive blocks. Registering locks `registrationBond` of
/// the robot's grant as its bond: it comes back to the robot `bondDelay` blocks after the robot leaves
/// the market (`exit`, then `withdrawBond`), and is forfeited (burned) when `registrarThreshold`
/// registrars revoke the robot (`revokeRegistration`), before or during that delay; `registrarThreshold`
/// + 1 registrars may reverse a revocation within `bondDelay` blocks (`reinstate`), minting the bond back. A depositor
/// submits a deposit only with its evidence: the robot's signature over its round trip and a nest's
/// acknowledgement of it. A
/// pauser stops registrations, reveals and deposits; settlements and expiries go on while paused, so no
/// stake is ever held by a pause. Only registered robots may buy, sell or be paid a reward (a record
/// revealed before its seller was revoked is still weighed and paid). A light
/// contract names the buyer's round trip it belongs to, so a reveal after the buyer's deposit is
/// refused rather than paid from the next item.
///
/// Fixed point: token amounts in units of 1e-9 token; positions and vectors in micro arena units
/// (signed); cos(theta) in units of 1e-9.
///
/// Modules (contracts/market/), composed as OpenZeppelin composes its contracts: {MarketStorage}
/// (constants, configuration, the whole state), {MarketRoles} (roles and pause), {MarketRegistration}
/// (registration and bond), {MarketEIP712} (domain and signed digests), {LightContracts} (reveals),
/// {MarketWeights} (each scheme's weights) and {MarketSettlement} (records and settlement); the
/// interface {IInformationMarket} documents every external function, event and error.
contract InformationMarket is MarketRegistration, LightContracts, MarketSettlement {
    /// @notice Deploys a market with a fixed payment scheme and its trust policy.
    /// @param market_ Account of the market node: it receives the admin, depositor and pauser roles.
    /// @param scheme_ Payment scheme.
    /// @param reward_ Reward R per item, 1e-9 units.
    /// @param informationShare_ Part of R shared with the sellers, as a WAD (0.5 = 5e17); at most 1e18.
    /// @param stake_ Stake per sale, 1e-9 units (0 = no staking); must be 0 under delayed payment.
    /// @param cosTheta_ cos(theta) of the similarity window, in units of 1e-9 (in [-1e9, 1e9]); two
    /// records are similar when the angle between their vectors is strictly less than theta.
    /// @param stakeExpiry_ Blocks after which a round trip's first record expires the round trip (>= 1).
    /// @param maxRecordsPerSeller_ Most records one seller may sell one buyer in one round trip (>= 1).
    /// @param maxRecordsPerTrip_ Most live records a buyer's open round trip may hold (1 to 512).
    /// @param maxValidity_ Furthest a light contract's last block may lie ahead of its reveal (>= 1).
    /// @param settleBatch_ Work units of one `buyItem`, `settle` or `refundExpired` call (1 to 48).
    /// @param settlementDeadline_ Blocks after `buyItem` from which any caller, registered or not, earns
    /// the bounty for continuing an unfinished settlement (>= 1); the rule it pays by never changes.
    /// @param maxGrant_ Most initial wealth the market may grant one robot, 1e-9 units.
    /// @param registrars_ Accounts that receive the registrar role (at least `registrarThreshold_`).
    /// @param registrarThreshold_ Distinct registrar approvals that register a robot (>= 1).
    /// @param registrarQuota_ Most approvals one registrar may make per period (>= 1).
    /// @param registrarPeriod_ Length of that period, blocks (>= 1).
    /// @param nest_ Account that receives the nest role (acknowledges deposits).
    /// @param settleBounty_ Paid to a registered robot per unit of settlement work it does, 1e-9 units;
    /// the bounty of the largest settlement must fit in the reward's share.
    /// @param registrationBond_ Bond every registration locks out of the grant, 1e-9 units (at most
    /// `maxGrant_`).
    /// @param bondDelay_ Blocks between a robot's `exit` and the return of its bond (1 to 2^40): the time the
    /// registrars have to revoke it.
    /// @param cap_ Under OutlierCapped, most records per seller that count in a round trip (>= 1; the
    /// reward and the stake below 2^96 units); 0 under every other scheme.
    constructor(
        address market_,
        Scheme scheme_,
        uint256 reward_,
        uint256 informationShare_,
        uint256 stake_,
        int256 cosTheta_,
        uint64 stakeExpiry_,
        uint256 maxRecordsPerSeller_,
        uint256 maxRecordsPerTrip_,
        uint64 maxValidity_,
        uint256 settleBatch_,
        uint64 settlementDeadline_,
        uint256 maxGrant_,
        address[] memory registrars_,
        uint256 registrarThreshold_,
        uint256 registrarQuota_,
        uint64 registrarPeriod_,
        address nest_,
        uint256 settleBounty_,
        uint256 registrationBond_,
        uint64 bondDelay_,
        uint256 cap_
    )
        MarketStorage(
            market_,
            scheme_,
            reward_,
            informationShare_,
            stake_,
            cosTheta_,
            stakeExpiry_,
            maxRecordsPerSeller_,
            maxRecordsPerTrip_,
            maxValidity_,
            settleBatch_,
            settlementDeadline_,
            maxGrant_,
            registrars_,
            registrarThreshold_,
            registrarQuota_,
            registrarPeriod_,
            nest_,
            settleBounty_,
            registrationBond_,
            bondDelay_,
            cap_
        )
        MarketRoles(market_, nest_, registrars_)
    {}
}
