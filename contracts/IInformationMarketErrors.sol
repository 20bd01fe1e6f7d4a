// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

/// @title IInformationMarketErrors
/// @notice The custom errors of the information market (EIP-6093 style: a domain prefix and the values
/// that tell a caller what went wrong); no call reverts with a string.
/// @dev Kept apart from {IInformationMarket}, as OpenZeppelin keeps its standard errors in an interface
/// of their own, so that a client decoding a revert needs only this list.
interface IInformationMarketErrors {
    /// @notice `caller` lacks `role`, which the call needs.
    /// @param caller Sender of the refused call.
    /// @param role The role it needs.
    error InfoMarketUnauthorized(address caller, bytes32 role);

    /// @notice Registrations, reveals and deposits are paused.
    error InfoMarketPaused();

    /// @notice `registrar` already approved this (robot, amount).
    /// @param registrar The registrar.
    /// @param robot The robot.
    error InfoMarketAlreadyApproved(address registrar, address robot);

    /// @notice `registrar` already approved `limit` registrations in the current period.
    /// @param registrar The registrar.
    /// @param limit `registrarQuota`.
    error InfoMarketRegistrarQuotaExceeded(address registrar, uint256 limit);

    /// @notice `registrar` has no standing approval of that request about `robot` to cancel.
    /// @param registrar The caller.
    /// @param robot The robot.
    error InfoMarketNotApproved(address registrar, address robot);

    /// @notice The deposit's robot signature does not recover to the robot (for its open round trip).
    /// @param robot The depositing robot.
    /// @param recovered Address the signature recovers to (zero when none).
    error InfoMarketInvalidDepositSignature(address robot, address recovered);

    /// @notice The deposit's acknowledgement is not signed by an account holding the nest role.
    /// @param robot The depositing robot.
    /// @param signer Address the acknowledgement recovers to (zero when none).
    error InfoMarketUnacknowledgedDeposit(address robot, address signer);

    /// @notice `caller` submitted a light contract whose seller is `seller`; only the seller may reveal.
    /// @param caller Sender of the refused reveal.
    /// @param seller Seller named in the offer.
    error InfoMarketUnauthorizedSeller(address caller, address seller);

    /// @notice The reveal came after the agreed last block.
    /// @param maxBlock Last block the light contract allowed.
    /// @param currentBlock Block the reveal would have been included in.
    error InfoMarketExpiredContract(uint64 maxBlock, uint256 currentBlock);

    /// @notice The light contract's last block lies further ahead than `maxValidity` blocks.
    /// @param maxBlock Last block the light contract asks for.
    /// @param limit The furthest block allowed now.
    error InfoMarketValidityTooLong(uint64 maxBlock, uint256 limit);

    /// @notice The buyer's signature does not recover to the buyer named in the light contract.
    /// @param buyer Buyer named in the light contract.
    /// @param recovered Address the signature recovers to (zero when it recovers to none).
    error InfoMarketInvalidBuyerSignature(address buyer, address recovered);

    /// @notice The signature's s lies in the upper half of the curve order (a malleated copy).
    /// @param s The refused s value.
    error InfoMarketMalleableSignature(bytes32 s);

    /// @notice This (site, age, max block, buyer, seller, path hash) sale was already revealed once.
    /// @param key The spent `revealKey`.
    error InfoMarketAlreadyRevealed(bytes32 key);

    /// @notice The revealed path information does not hash to the committed value.
    /// @param committed Hash in the light contract.
    /// @param revealed Hash of the revealed information.
    error InfoMarketInformationMismatch(bytes32 committed, bytes32 revealed);

    /// @notice The seller cannot lock the stake the market requires for a sale.
    /// @param robot The seller.
    /// @param balance Its free balance.
    /// @param needed The stake.
    error InfoMarketInsufficientStake(address robot, uint256 balance, uint256 needed);

    /// @notice A robot tried to sell to itself.
    /// @param robot Both buyer and seller.
    error InfoMarketSelfDealing(address robot);

    /// @notice The site code is neither food (0) nor nest (1).
    /// @param site The refused code.
    error InfoMarketInvalidSite(uint8 site);

    /// @notice The seller's vector (purchased vector minus seller position) has a component of
    /// magnitude 2^47 micro units or more, beyond what the similarity test computes exactly.
    /// @param dx Its x component.
    /// @param dy Its y component.
    error InfoMarketVectorOutOfRange(int256 dx, int256 dy);

    /// @notice The seller already sold `limit` records to this buyer in its current round trip.
    /// @param buyer The buyer.
    /// @param seller The seller.
    /// @param limit `maxRecordsPerSeller`.
    error InfoMarketTooManyRecords(address buyer, address seller, uint256 limit);

    /// @notice The buyer's open round trip already holds `limit` live records.
    /// @param buyer The buyer.
    /// @param limit `maxRecordsPerTrip`.
    error InfoMarketTripFull(address buyer, uint256 limit);

    /// @notice `seller` already sold in `buyer`'s open round trip, and its further record would take room
    /// kept for sellers not yet heard: further records take at most half of the room first records leave,
    /// 2 * `repeats` + first records <= `maxRecordsPerTrip`.
    /// @param buyer The buyer.
    /// @param seller The seller refused.
    /// @param repeats Further records (a seller's second and later) the round trip already holds.
    error InfoMarketTripReserved(address buyer, address seller, uint256 repeats);

    /// @notice The light contract was signed for another of the buyer's round trips (a reveal must land
    /// before the buyer's next deposit).
    /// @param buyer The buyer.
    /// @param signed The round trip the buyer signed for.
    /// @param current The buyer's open round trip.
    error InfoMarketWrongTrip(address buyer, uint64 signed, uint64 current);

    /// @notice `robot` was never registered by the market (`grantWealth`).
    /// @param robot The unregistered account.
    error InfoMarketUnregistered(address robot);

    /// @notice `robot` is already registered: the market grants initial wealth once per robot.
    /// @param robot The account.
    error InfoMarketAlreadyRegistered(address robot);

    /// @notice The grant does not cover the bond a registration locks.
    /// @param amount The refused grant.
    /// @param bond `registrationBond`.
    error InfoMarketGrantBelowBond(uint256 amount, uint256 bond);

    /// @notice `robot` has no bond waiting to be withdrawn (it did not `exit`, or its bond is gone).
    /// @param robot The robot.
    error InfoMarketNotExiting(address robot);

    /// @notice `robot` has no revocation that can still be reversed (not revoked, or its appeal window
    /// ended at block `until`).
    /// @param robot The robot.
    /// @param until Last block of the appeal window (0 when not revoked).
    error InfoMarketNotRevoked(address robot, uint64 until);

    /// @notice `robot`'s bond is locked until block `unlockBlock`.
    /// @param robot The robot.
    /// @param unlockBlock First block of `withdrawBond`.
    error InfoMarketBondLocked(address robot, uint256 unlockBlock);

    /// @notice The grant exceeds `maxGrant`.
    /// @param amount The refused grant.
    /// @param limit `maxGrant`.
    error InfoMarketGrantTooLarge(uint256 amount, uint256 limit);

    /// @notice The robot's previous round trip is still being settled: call `settle` first.
    /// @param robot The robot.
    /// @param remaining Records its settlement still has to process.
    error InfoMarketSettlementPending(address robot, uint256 remaining);

    /// @notice There is no deposited round trip of `robot` to settle.
    /// @param robot The robot.
    error InfoMarketNothingToSettle(address robot);

    /// @notice A constructor argument is out of range.
    /// @param parameter Name of the argument (ASCII, right-padded with zeros).
    /// @param value Its value.
    error InfoMarketInvalidParameter(bytes32 parameter, int256 value);
}
