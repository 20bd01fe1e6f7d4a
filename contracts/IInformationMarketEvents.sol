// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

/// @title IInformationMarketEvents
/// @notice The events of the information market, past tense, each emitted right after the state change
/// it reports: the record a client replays to follow every movement of money.
interface IInformationMarketEvents {
    /// @notice The market granted `amount` new tokens to `robot` (initial wealth).
    /// @param robot Receiving account.
    /// @param amount Tokens minted, 1e-9 units.
    event WealthGranted(address indexed robot, uint256 amount);

    /// @notice `seller` locked `amount` as stake for a sale to `buyer`; it joins the buyer's pot.
    /// @param seller Account whose balance paid the stake.
    /// @param buyer Account whose pot holds it until its next deposit.
    /// @param amount Stake, 1e-9 units.
    event StakeLocked(address indexed seller, address indexed buyer, uint256 amount);

    /// @notice A light contract was executed and its path information revealed. The event carries all
    /// a record's weight depends on, so a settlement can be recomputed from the logs alone.
    /// @param buyer Buyer of the information.
    /// @param seller Seller of the information.
    /// @param key `revealKey(site, age, maxBlock, buyer, seller, pathHash)`, now spent.
    /// @param index Position of the record in the buyer's list (`_records[buyer][index]`).
    /// @param site 0 = food, 1 = nest.
    /// @param age Age of the information.
    /// @param x Revealed vector, x, micro units, buyer's frame.
    /// @param y Revealed vector, y.
    /// @param sellerX Seller's position in the buyer's frame (signed by the buyer), x.
    /// @param sellerY Same, y.
    /// @param pathHash The commitment the revealed information matched.
    event InformationRevealed(
        address indexed buyer,
        address indexed seller,
        bytes32 indexed key,
        uint256 index,
        uint8 site,
        uint32 age,
        int64 x,
        int64 y,
        int64 sellerX,
        int64 sellerY,
        bytes32 pathHash
    );

    /// @notice `buyer`'s open round trip expired (its first record is `stakeExpiry` blocks old, or the
    /// buyer is no longer registered) and was closed for settlement as a deposit closes it: its records
    /// are weighed and paid ({RewardShared}) from its stakes and `share`, which the buyer paid from its
    /// balance (the reward's share, or the whole balance when that is less).
    /// @param buyer The buyer.
    /// @param share Paid by the buyer into the settlement, 1e-9 units.
    /// @param pot Stakes of the round trip.
    /// @param transactions Number of records in the round trip.
    event RoundTripExpired(address indexed buyer, uint256 share, uint256 pot, uint256 transactions);

    /// @notice The market paid `robot` the reward for one item and closed its round trip for settlement.
    /// @param robot Depositing robot.
    /// @param reward Reward minted to it, 1e-9 units.
    /// @param pot Stakes of the round trip.
    /// @param transactions Number of records in the round trip (each is weighed and paid).
    event ItemBought(address indexed robot, uint256 reward, uint256 pot, uint256 transactions);

    /// @notice One record's seller received its share of a deposit.
    /// @param robot Depositing robot (the buyer of the information).
    /// @param seller Receiving seller.
    /// @param index The record.
    /// @param weight The record's weight (1 under delayed payment, similar-transaction count under
    /// outlier, distinct-seller count * 1e27 / the seller's records for the site under outlier-distinct;
    /// under outlier-capped stake * C for a void record and (share + counted records * stake) * its count
    /// for a counted one, C the counts' sum).
    /// @param amount Share paid, 1e-9 units.
    event RewardShared(address indexed robot, address indexed seller, uint256 index, uint256 weight, uint256 amount);

    /// @notice `caller` earned `amount` for settling `robot`'s deposit (`settleBounty` per unit of work).
    /// @param caller The registered robot that called `settle`.
    /// @param robot The depositing robot.
    /// @param amount Bounty paid, 1e-9 units.
    event SettlementBountyPaid(address indexed caller, address indexed robot, uint256 amount);

    /// @notice `registrar` approved registering `robot` with initial wealth `amount`.
    /// @param registrar The approving registrar.
    /// @param robot The robot.
    /// @param amount The grant approved, 1e-9 units.
    /// @param approvals Distinct registrars that approved this (robot, amount) so far.
    event RegistrationApproved(address indexed registrar, address indexed robot, uint256 amount, uint256 approvals);

    /// @notice `robot`'s registration locked `amount` of its grant as its bond.
    /// @param robot The robot.
    /// @param amount The bond, 1e-9 units.
    event BondLocked(address indexed robot, uint256 amount);

    /// @notice `robot` left the market; its bond may be withdrawn from block `unlockBlock` on.
    /// @param robot The robot.
    /// @param unlockBlock First block of `withdrawBond`.
    event ExitRequested(address indexed robot, uint256 unlockBlock);

    /// @notice `robot`'s bond went back to its balance after a clean exit.
    /// @param robot The robot.
    /// @param amount The bond, 1e-9 units.
    event BondReturned(address indexed robot, uint256 amount);

    /// @notice `registrar` approved revoking `robot`.
    /// @param registrar The approving registrar.
    /// @param robot The robot.
    /// @param approvals Distinct registrars that approved revoking it so far.
    event RevocationApproved(address indexed registrar, address indexed robot, uint256 approvals);

    /// @notice `registrar` withdrew its approval of `request` (a registration or a revocation of `robot`).
    /// @param registrar The registrar.
    /// @param robot The robot.
    /// @param request keccak256(abi.encode(robot, amount)) or keccak256(abi.encode("revoke", robot)).
    event ApprovalCancelled(address indexed registrar, address indexed robot, bytes32 request);

    /// @notice `robot` was revoked and its bond burned.
    /// @param robot The robot.
    /// @param amount The bond, 1e-9 units.
    event BondForfeited(address indexed robot, uint256 amount);

    /// @notice `registrar` approved reversing `robot`'s revocation.
    /// @param registrar The approving registrar.
    /// @param robot The robot.
    /// @param approvals Distinct registrars that approved reinstating it so far.
    event ReinstatementApproved(address indexed registrar, address indexed robot, uint256 approvals);

    /// @notice `robot`'s revocation was reversed: it is registered again (or exiting again, when it was),
    /// with its bond restored.
    /// @param robot The robot.
    /// @param bond The bond restored (minted again), 1e-9 units.
    event RegistrationReinstated(address indexed robot, uint256 bond);

    /// @notice `account` received `role` from `sender`.
    /// @param role The role.
    /// @param account The account.
    /// @param sender The admin that granted it.
    event RoleGranted(bytes32 indexed role, address indexed account, address indexed sender);

    /// @notice `account` lost `role` (revoked by an admin, or renounced by `account` itself).
    /// @param role The role.
    /// @param account The account.
    /// @param sender Who revoked it.
    event RoleRevoked(bytes32 indexed role, address indexed account, address indexed sender);

    /// @notice Registrations, reveals and deposits stopped (`paused` true) or resumed.
    /// @param account The pauser.
    /// @param paused The new state.
    event PauseSet(address indexed account, bool paused);

    /// @notice A round trip's settlement finished: `shared` went to the sellers of its live records and
    /// `kept` (rounding dust, or the whole share when the round trip had no record) back to `robot`.
    /// @param robot Depositing robot.
    /// @param shared Sum of the shares paid.
    /// @param kept Returned to the robot.
    /// @param totalWeight Sum of the live records' weights (under OutlierCapped, of their counts: C).
    event SettlementCompleted(address indexed robot, uint256 shared, uint256 kept, uint256 totalWeight);
}
