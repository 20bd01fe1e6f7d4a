// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {IInformationMarketErrors} from "./IInformationMarketErrors.sol";
import {IInformationMarketEvents} from "./IInformationMarketEvents.sol";

/// @title IInformationMarket
/// @notice What the on-chain information market offers its robots, nests and operators: the types of its
/// calls, and every external function with its rules (the implementation, {InformationMarket}, inherits
/// this documentation). Functions are grouped by the module that implements them.
interface IInformationMarket is IInformationMarketErrors, IInformationMarketEvents {
    // ------------------------------------------------------------------------------------------------
    // Types
    // ------------------------------------------------------------------------------------------------

    /// @notice How a deposit's reward share is split among the robot's sellers (docs/model.md §5).
    /// @dev Delayed: in proportion to each seller's number of transactions; no stakes allowed.
    /// Outlier: in proportion to the number of same-site transactions within theta of each transaction,
    /// with the locked stakes added to the shared amount (staking is on when `stake() > 0`).
    /// OutlierDistinct: like Outlier, but a transaction weighs the number of distinct sellers with a
    /// same-site transaction within theta (its own seller once), divided by its seller's number of
    /// transactions for that site in the round trip: one seller, one voice (docs/chain.md).
    /// OutlierCapped: at most `cap` records per seller count in a round trip (its first live ones); a
    /// later one is void: paid its stake back (scaled as the live records' amount is, when some records
    /// expired), it earns nothing and counts in nobody's weight. The counted records are weighed as under
    /// Outlier among themselves and share the rest (docs/defences.md, `capped_outlier`).
    enum Scheme {
        Delayed,
        Outlier,
        OutlierDistinct,
        OutlierCapped
    }

    /// @notice The seller's offer, which the buyer accepts without seeing the information itself.
    /// @param seller Account that sells and must submit the reveal.
    /// @param site 0 = food, 1 = nest.
    /// @param age Age of the offered information, in simulation steps.
    /// @param maxBlock Last block in which the reveal may be included (at most `maxValidity` ahead).
    /// @param pathHash `keccak256(abi.encode(x, y, salt))` of the `PathInfo` to be revealed.
    struct Offer {
        address seller;
        uint8 site;
        uint32 age;
        uint64 maxBlock;
        bytes32 pathHash;
    }

    /// @notice A light contract: the offer plus the buyer's acceptance and its signature over both.
    /// @param offer The seller's offer.
    /// @param buyer Account that accepted and whose next deposit pays the seller.
    /// @param sellerX Seller's position in the buyer's frame, x, micro units (signed by the buyer).
    /// @param sellerY Same, y.
    /// @param trip The buyer's round trip the sale belongs to (`roundTrip(buyer)` when signed).
    /// @param v Buyer's signature over the EIP-712 `Acceptance` digest: recovery byte (27 or 28).
    /// @param r Signature r.
    /// @param s Signature s, in the lower half of the curve order.
    struct LightContract {
        Offer offer;
        address buyer;
        int64 sellerX;
        int64 sellerY;
        uint64 trip;
        uint8 v;
        bytes32 r;
        bytes32 s;
    }

    /// @notice The revealed path information, in the buyer's frame. There is no declared direction:
    /// the contract derives it from the vector.
    /// @param x Purchased vector to the site, x, micro units (rotated offer plus seller position).
    /// @param y Same, y.
    /// @param salt Seller's random nonce, so that the committed hash cannot be inverted by guessing.
    struct PathInfo {
        int64 x;
        int64 y;
        bytes32 salt;
    }

    /// @notice One sale recorded under its buyer until the buyer's deposit settles it (two slots; the
    /// second holds all that weighing reads).
    /// @param seller Who sold it.
    /// @param openedAt Block of the reveal (its expiry counts from there).
    /// @param site 0 = food, 1 = nest.
    /// @param dx The seller's rotated vector in the buyer's frame (purchased vector minus the seller's
    /// position), x, micro units; a zero vector is stored as (1, 0), direction 0 like atan2(0, 0).
    /// @param dy Same, y.
    /// @param weight The record's weight, written while its round trip is settled (under
    /// OutlierDistinct scaled by 1e27: distinct sellers * 1e27 / the seller's records for the site; under
    /// OutlierCapped the count of similar counted records, 0 for a void record).
    /// @param prevGap How many records back the same seller's previous record of this round trip lies
    /// (0: none within reach).
    struct Information {
        address seller;
        uint64 openedAt;
        uint8 site;
        int64 dx;
        int64 dy;
        uint104 weight;
        uint16 prevGap;
    }

    /// @notice What a deposit carries: the robot's signature over `Deposit(robot, trip)` (it ends that
    /// round trip) and a nest's signature over the same message (it received the item).
    struct DepositEvidence {
        uint8 robotV;
        bytes32 robotR;
        bytes32 robotS;
        uint8 nestV;
        bytes32 nestR;
        bytes32 nestS;
    }

    // ------------------------------------------------------------------------------------------------
    // Role identifiers (MarketRoles)
    // ------------------------------------------------------------------------------------------------

    /// @notice Role that grants and revokes every role (as AccessControl's DEFAULT_ADMIN_ROLE).
    function ADMIN_ROLE() external view returns (bytes32);

    /// @notice Role whose holders approve registrations (`grantWealth`).
    function REGISTRAR_ROLE() external view returns (bytes32);

    /// @notice Role whose holders submit deposits (`buyItem`).
    function DEPOSITOR_ROLE() external view returns (bytes32);

    /// @notice Role whose holders acknowledge deposits (sign `Deposit(robot, trip)`).
    function NEST_ROLE() external view returns (bytes32);

    /// @notice Role whose holders pause and unpause.
    function PAUSER_ROLE() external view returns (bytes32);

    // ------------------------------------------------------------------------------------------------
    // Roles and pause (MarketRoles)
    // ------------------------------------------------------------------------------------------------

    /// @notice Gives `role` to `account` (a second key, or the new key of a rotation).
    /// @dev Requirements: the caller is an admin. Emits {RoleGranted} when it was not held.
    /// @param role The role.
    /// @param account The account.
    function grantRole(bytes32 role, address account) external;

    /// @notice Takes `role` from `account` (the old key of a rotation, or a compromised one).
    /// @dev Requirements: the caller is an admin. Emits {RoleRevoked} when it was held.
    /// @param role The role.
    /// @param account The account.
    function revokeRole(bytes32 role, address account) external;

    /// @notice Gives up `role` held by the caller.
    /// @param role The role.
    function renounceRole(bytes32 role) external;

    /// @notice Stops (`paused_` true) or resumes registrations, reveals and deposits. Settlements and
    /// expiries (`refundExpired`) never stop.
    /// @dev Requirements: the caller is a pauser. Emits {PauseSet} when the state changes.
    /// @param paused_ The new state.
    function setPaused(bool paused_) external;

    /// @notice Whether `account` holds `role`.
    /// @param role The role.
    /// @param account The account.
    /// @return True when held.
    function hasRole(bytes32 role, address account) external view returns (bool);

    /// @notice Whether registrations, reveals and deposits are paused.
    /// @return True when paused.
    function paused() external view returns (bool);

    // ------------------------------------------------------------------------------------------------
    // Registration and bond (MarketRegistration)
    // ------------------------------------------------------------------------------------------------

    /// @notice Approves registering `robot` with `amount` tokens of initial wealth (0 allowed); the
    /// `registrarThreshold`-th distinct registrar to approve the same (robot, amount) registers it and
    /// mints the grant. Only registered robots may buy, sell or deposit.
    /// The registration locks `registrationBond` of the grant as the robot's bond.
    /// @dev Requirements: the caller is a registrar within its quota (at most `registrarQuota` approvals
    /// in any `registrarPeriod` consecutive blocks); not paused; `robot` is not registered and never was;
    /// `amount` covers the bond and is at most `maxGrant`; the caller's approval of this (robot, amount)
    /// does not stand already. Only standing approvals count (`_stands`). Emits {RegistrationApproved}, and
    /// {WealthGranted} and {BondLocked} when it registers.
    /// @param robot Receiving account.
    /// @param amount Tokens, 1e-9 units.
    /// @return registered Whether this approval registered the robot.
    function grantWealth(address robot, uint256 amount) external returns (bool registered);

    /// @notice The caller leaves the market: it may no longer buy, sell or deposit, and its bond comes
    /// back with `withdrawBond` from `bondDelay` blocks on, unless the registrars revoke it meanwhile.
    /// Its sales still pending are paid as usual.
    /// @dev Requirements: the caller is registered. Emits {ExitRequested}.
    function exit() external;

    /// @notice Returns `robot`'s bond to its balance after its exit delay; anyone may call it.
    /// @dev Requirements: `robot` exited and was not revoked; the delay has passed. Emits {BondReturned}.
    /// @param robot The exited robot.
    /// @return amount The bond returned, 1e-9 units.
    function withdrawBond(address robot) external returns (uint256 amount);

    /// @notice Approves revoking `robot` (registered, or exited within its bond delay); the
    /// `registrarThreshold`-th distinct registrar to approve revokes it: it may no longer buy, sell or
    /// deposit, nor register again, and its bond is burned, unless more registrars reverse it within
    /// `bondDelay` blocks (`reinstate`). Works while paused.
    /// @dev Requirements: the caller is a registrar within its quota (as for `grantWealth`) whose approval of
    /// revoking `robot` does not stand already (only standing approvals count); `robot`
    /// holds a bond. Emits {RevocationApproved}, and {BondForfeited} when it revokes.
    /// @param robot The robot.
    /// @return revoked Whether this approval revoked it.
    function revokeRegistration(address robot) external returns (bool revoked);

    /// @notice Approves reversing `robot`'s revocation, within `bondDelay` blocks of it; the
    /// (`registrarThreshold` + 1)-th distinct registrar to approve reinstates it: registered again (or
    /// exiting again, its bond withdrawable `bondDelay` blocks later, when it was exiting), its bond
    /// minted back. More registrars must agree to reverse a revocation than to make one, so the keys
    /// that revoked cannot undo an honest majority's revocation, and a revocation by compromised keys is
    /// reversed by the others once the admin has replaced those keys. Works while paused.
    /// @dev Requirements: the caller is a registrar within its quota (reinstatements count against it as
    /// revocations do) whose approval does not stand already; `robot` was revoked less than `bondDelay`
    /// blocks ago. Approvals of revoking and of reinstating a robot count anew after each reinstatement.
    /// Emits {ReinstatementApproved}, and {RegistrationReinstated} when it reinstates.
    /// @param robot The robot.
    /// @return reinstated Whether this approval reinstated it.
    function reinstate(address robot) external returns (bool reinstated);

    /// @notice Withdraws the caller's standing approval of registering `robot` with `amount`.
    /// @dev Requirements: the approval stands. Emits {ApprovalCancelled}.
    /// @param robot The robot.
    /// @param amount The grant approved.
    function cancelApproval(address robot, uint256 amount) external;

    /// @notice Withdraws the caller's standing approval of revoking `robot`.
    /// @dev Requirements: the approval stands. Emits {ApprovalCancelled}.
    /// @param robot The robot.
    function cancelRevocation(address robot) external;

    /// @notice Approvals the registration of `robot` with `amount` has so far.
    /// @param robot The robot.
    /// @param amount The grant.
    /// @return The number of distinct registrars that approved it.
    function approvals(address robot, uint256 amount) external view returns (uint256);

    /// @notice Whether the market registered `robot`.
    /// @param robot The account.
    /// @return True once registered.
    function isRegistered(address robot) external view returns (bool);

    /// @notice The bond `robot` has locked (registered, or exited and not yet withdrawn; 0 otherwise).
    /// @param robot The account.
    /// @return The bond, 1e-9 units.
    function bondOf(address robot) external view returns (uint256);

    // ------------------------------------------------------------------------------------------------
    // EIP-712 (MarketEIP712)
    // ------------------------------------------------------------------------------------------------

    /// @notice The EIP-712 digest a robot and a nest sign for the deposit that ends round trip `trip`.
    /// @param robot The depositing robot.
    /// @param trip Its round trip.
    /// @return The digest of `Deposit(robot, trip)`.
    function depositDigest(address robot, uint64 trip) external view returns (bytes32);

    /// @notice The EIP-712 digest the buyer signs to accept `offer` (for clients to cross-check).
    /// @param offer The offer.
    /// @param buyer The buyer.
    /// @param sellerX Seller's position in the buyer's frame, x.
    /// @param sellerY Same, y.
    /// @param trip The buyer's round trip.
    /// @return The digest.
    function acceptanceDigest(Offer calldata offer, address buyer, int64 sellerX, int64 sellerY, uint64 trip)
        external
        view
        returns (bytes32);

    /// @notice The EIP-712 domain (EIP-5267), so that clients sign for this contract on this chain only.
    /// @return fields Bit mask of the fields used (name, version, chainId, verifyingContract).
    /// @return name "InformationMarket".
    /// @return version "4".
    /// @return chainId Current chain id.
    /// @return verifyingContract This contract.
    /// @return salt Unused.
    /// @return extensions None.
    function eip712Domain()
        external
        view
        returns (
            bytes1 fields,
            string memory name,
            string memory version,
            uint256 chainId,
            address verifyingContract,
            bytes32 salt,
            uint256[] memory extensions
        );

    // ------------------------------------------------------------------------------------------------
    // Light contracts (LightContracts)
    // ------------------------------------------------------------------------------------------------

    /// @notice Executes a light contract: records the sale under the buyer, reveals the path information
    /// and locks the seller's stake.
    /// @dev Checks, each with its own error: the seller is the caller; the current block is at most the
    /// agreed max block, which lies at most `maxValidity` blocks ahead; buyer and seller are registered;
    /// the buyer's EIP-712 signature over the acceptance is valid and not malleable; it names the
    /// buyer's open round trip; (site, age, max block, buyer, seller, path hash) was never revealed
    /// before; not paused; the information hashes to the committed value; the seller's vector is in range; the
    /// round trip holds fewer than `maxRecordsPerTrip` live records; the seller has not reached
    /// `maxRecordsPerSeller` in this round trip; it can lock the stake.
    /// Emits {StakeLocked} (under staking) and {InformationRevealed}.
    /// @param lc The double-signed light contract.
    /// @param info The path information in the buyer's frame.
    function revealInformation(LightContract calldata lc, PathInfo calldata info) external;

    /// @notice The identity of a sale for the never-twice check: the paper's tuple and the committed
    /// information, so two different sales with the same (site, age, max block) are both allowed.
    /// @param site Site code.
    /// @param age Information age.
    /// @param maxBlock Agreed last block.
    /// @param buyer Buyer.
    /// @param seller Seller.
    /// @param pathHash The commitment.
    /// @return `keccak256(abi.encode(site, age, maxBlock, buyer, seller, pathHash))`.
    function revealKey(uint8 site, uint32 age, uint64 maxBlock, address buyer, address seller, bytes32 pathHash)
        external
        pure
        returns (bytes32);

    /// @notice Whether the light contract identified by `key` was already revealed.
    /// @param key A `revealKey`.
    /// @return True once revealed.
    function isRevealed(bytes32 key) external view returns (bool);

    /// @notice The records of `buyer`'s open round trip (not yet deposited nor expired), in reveal order.
    /// @param buyer The account.
    /// @return list Its contributors' records.
    function contributors(address buyer) external view returns (Information[] memory list);

    /// @notice The round trip of `buyer` that light contracts signed now belong to (it grows by one at
    /// each of the buyer's deposits).
    /// @param buyer The account.
    /// @return The open round trip's number.
    function roundTrip(address buyer) external view returns (uint64);

    // ------------------------------------------------------------------------------------------------
    // Weights (MarketWeights)
    // ------------------------------------------------------------------------------------------------

    /// @notice Whether two seller vectors are similar: the angle between them is strictly less than
    /// theta. Exposed so that clients and tests can check the rule on its own; components must be below
    /// 2^47 in magnitude, as on the reveal path (`InfoMarketVectorOutOfRange` otherwise).
    /// @param ax First vector, x.
    /// @param ay First vector, y.
    /// @param bx Second vector, x.
    /// @param by Second vector, y.
    /// @return Whether they are similar.
    function similar(int64 ax, int64 ay, int64 bx, int64 by) external view returns (bool);

    // ------------------------------------------------------------------------------------------------
    // Settlement (MarketSettlement)
    // ------------------------------------------------------------------------------------------------

    /// @notice Buys the item `robot` deposited: pays it the reward, closes its round trip and settles
    /// up to `settleBatch` records of it; `settle` finishes the rest.
    /// @dev The reward share and the pot go into the settlement's escrow. Settling weighs every record
    /// of the round trip (expired or not: a deposit is a prompt one) and pays each floor(amount * w / sum w);
    /// the remainder goes back to `robot`, so the supply changes by exactly the reward.
    /// Requirements: the caller is a depositor; not paused; the robot is registered; its previous round
    /// trip is fully settled; the evidence holds the robot's signature over `Deposit(robot, trip)` for
    /// its open round trip and a nest's signature over the same. Emits {ItemBought}, then what
    /// {settle} emits.
    /// @param robot The depositing robot.
    /// @param evidence The robot's and the nest's signatures.
    /// @return done Whether the round trip is fully settled.
    function buyItem(address robot, DepositEvidence calldata evidence) external returns (bool done);

    /// @notice Continues the settlement of `robot`'s deposited round trip for at most `maxRecords`
    /// records of work; anyone may call it (it moves money only by the market's rules), and a
    /// registered caller (any caller from `settlementDeadline` blocks after the deposit) earns `settleBounty`
    /// per unit of work, from the share.
    /// @dev Requirements: a settlement is pending. Emits {RewardShared},
    /// {SettlementBountyPaid} and, at the end, {SettlementCompleted}.
    /// @param robot The depositing robot.
    /// @param maxRecords Work bound, capped at `settleBatch`: each record paid counts one,
    /// each record weighed ceil(m / 64) for m live records (at least one record is weighed when the
    /// bound is `settleBatch`, so the default batch always makes progress).
    /// @return done Whether the round trip is now fully settled.
    function settle(address robot, uint256 maxRecords) external returns (bool done);

    /// @notice Settles `buyer`'s open round trip once it can no longer be deposited in time: its first
    /// record opened `stakeExpiry` blocks ago or more, or the buyer is no longer registered (revoked or
    /// exited, it can never deposit). The round trip is closed as a deposit closes it, and every record
    /// is weighed and paid as a prompt deposit would pay it, from its stakes and the reward's share,
    /// which the buyer pays from its balance as far as that goes; the buyer's next deposit starts a new
    /// round trip and keeps the whole reward when that one is empty. So a seller is never better off
    /// because its records expired, and a buyer that waits for expiry still pays the share. Anyone may
    /// call it; a registered caller earns the bounty, as for `settle`, which finishes the rest.
    /// @dev Requirements: no settlement of `buyer` is pending (`settle` it first). Does nothing (returns
    /// 0) when the round trip is empty or has not expired. Emits {RoundTripExpired}, then what {settle} emits.
    /// @param buyer The buyer.
    /// @param maxRecords Work bound of this call, as for `settle` (capped at `settleBatch`).
    /// @return refunded How many records the closed round trip holds.
    function refundExpired(address buyer, uint256 maxRecords) external returns (uint256 refunded);

    /// @notice Free (unlocked) balance of `robot`, 1e-9 units.
    /// @param robot The account.
    /// @return The balance.
    function balanceOf(address robot) external view returns (uint256);

    /// @notice Stakes and shares locked under `buyer`: the pot of its open round trip plus what its
    /// pending settlement still holds.
    /// @param buyer The account.
    /// @return The locked amount, 1e-9 units.
    function lockedStake(address buyer) external view returns (uint256);

    /// @notice Whether `robot` has a deposited round trip still to settle, and where it stands.
    /// @param robot The account.
    /// @return pending True until the settlement completes.
    /// @return phase 0 closed (nothing done yet), 1 weighing, 2 paying.
    /// @return remaining Records left in the current phase.
    function pendingSettlement(address robot) external view returns (bool pending, uint8 phase, uint256 remaining);

    /// @notice Tokens in existence: all balances plus everything locked.
    /// @return The supply, 1e-9 units.
    function totalSupply() external view returns (uint256);

    /// @notice Decimals of the token amounts (1 token = 1e9 units).
    /// @return Always 9.
    function decimals() external pure returns (uint8);

    // ------------------------------------------------------------------------------------------------
    // Configuration (MarketStorage)
    // ------------------------------------------------------------------------------------------------

    /// @notice The market's configuration (the constructor's economic arguments; `policy` has the rest).
    /// @return scheme_ Payment scheme.
    /// @return reward_ Reward per item, 1e-9 units.
    /// @return informationShare_ Shared part of the reward, WAD.
    /// @return stake_ Stake per sale, 1e-9 units.
    /// @return cosTheta_ cos(theta), 1e-9 units.
    /// @return stakeExpiry_ Blocks before a record expires.
    /// @return maxRecordsPerSeller_ Most records per seller, buyer and round trip.
    /// @return maxRecordsPerTrip_ Most live records per round trip.
    /// @return maxValidity_ Furthest a light contract's last block may lie ahead.
    /// @return settleBatch_ Work units per call.
    /// @return settlementDeadline_ Blocks after a deposit from which any caller earns the settle bounty.
    /// @return maxGrant_ Most initial wealth per robot.
    /// @return settleBounty_ Bounty per unit of settlement work.
    /// @return cap_ Most records per seller that count in a round trip under OutlierCapped (0 otherwise).
    function configuration()
        external
        view
        returns (
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
            uint256 settleBounty_,
            uint256 cap_
        );

    /// @notice The registration policy.
    /// @return threshold Distinct registrar approvals that register (or revoke) a robot.
    /// @return quota Most approvals per registrar per period.
    /// @return period Its length, blocks.
    /// @return bond Bond a registration locks, 1e-9 units.
    /// @return bondDelay Blocks from a robot's exit to the return of its bond.
    function policy()
        external
        view
        returns (uint256 threshold, uint256 quota, uint64 period, uint256 bond, uint64 bondDelay);
}
