// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {IInformationMarket} from "../IInformationMarket.sol";
import {MarketRoles} from "./MarketRoles.sol";

/// @title MarketRegistration
/// @notice Registration and bond: registrars approve a robot's registration (with its initial wealth)
/// and its revocation, each by `registrarThreshold` distinct standing approvals within a quota; a
/// registration locks a bond that comes back `bondDelay` blocks after the robot exits, is burned when
/// it is revoked, and is minted back when more registrars reverse the revocation.
/// @dev An identity's life is `_registered` plus `_exits[robot]` (exiting, closed, revoked); approvals
/// are per request hash, counted by `_standing` over the keys that approved it.
abstract contract MarketRegistration is MarketRoles {
    /// @inheritdoc IInformationMarket
    function grantWealth(address robot, uint256 amount) external returns (bool registered) {
        _requireRole(REGISTRAR_ROLE);
        _requireNotPaused();
        if (_registered[robot] || _exits[robot].state != 0) revert InfoMarketAlreadyRegistered(robot);
        if (amount > _maxGrant) revert InfoMarketGrantTooLarge(amount, _maxGrant);
        if (amount < _registrationBond) revert InfoMarketGrantBelowBond(amount, _registrationBond);
        uint256 count = _approve(keccak256(abi.encode(robot, amount)), robot);
        emit RegistrationApproved(msg.sender, robot, amount, count);
        if (count < _registrarThreshold) return false;
        registered = true;
        _registered[robot] = true;
        _balances[robot] += amount - _registrationBond;
        _totalSupply += amount;
        emit WealthGranted(robot, amount);
        emit BondLocked(robot, _registrationBond);
    }

    /// @inheritdoc IInformationMarket
    function exit() external {
        if (!_registered[msg.sender]) revert InfoMarketUnregistered(msg.sender);
        _registered[msg.sender] = false;
        uint64 at = uint64(block.number) + _bondDelay;
        _exits[msg.sender] = Exit(at, _EXITING, _exits[msg.sender].reinstated, false);
        emit ExitRequested(msg.sender, at);
    }

    /// @inheritdoc IInformationMarket
    function withdrawBond(address robot) external returns (uint256 amount) {
        Exit storage e = _exits[robot];
        if (e.state != _EXITING) revert InfoMarketNotExiting(robot);
        if (block.number < e.at) revert InfoMarketBondLocked(robot, e.at);
        e.state = _CLOSED;
        amount = _registrationBond;
        _balances[robot] += amount;
        emit BondReturned(robot, amount);
    }

    /// @inheritdoc IInformationMarket
    function revokeRegistration(address robot) external returns (bool revoked) {
        _requireRole(REGISTRAR_ROLE);
        Exit storage e = _exits[robot];
        if (!_registered[robot] && e.state != _EXITING) revert InfoMarketUnregistered(robot);
        uint256 count = _approve(keccak256(abi.encode("revoke", robot, e.reinstated)), robot);
        emit RevocationApproved(msg.sender, robot, count);
        revoked = count >= _registrarThreshold;
        if (!revoked) return false;
        _registered[robot] = false;
        e.exiting = e.state == _EXITING;
        e.state = _REVOKED;
        e.at = uint64(block.number) + _bondDelay;
        _totalSupply -= _registrationBond;
        emit BondForfeited(robot, _registrationBond);
    }

    /// @inheritdoc IInformationMarket
    function reinstate(address robot) external returns (bool reinstated) {
        _requireRole(REGISTRAR_ROLE);
        Exit storage e = _exits[robot];
        if (e.state != _REVOKED || block.number >= e.at) revert InfoMarketNotRevoked(robot, e.at);
        uint256 count = _approve(keccak256(abi.encode("reinstate", robot, e.reinstated)), robot);
        emit ReinstatementApproved(msg.sender, robot, count);
        reinstated = count > _registrarThreshold;
        if (!reinstated) return false;
        e.reinstated += 1;
        if (e.exiting) {
            e.state = _EXITING;
            e.at = uint64(block.number) + _bondDelay;
        } else {
            e.state = 0;
            e.at = 0;
            _registered[robot] = true;
        }
        _totalSupply += _registrationBond;
        emit RegistrationReinstated(robot, _registrationBond);
    }

    /// @inheritdoc IInformationMarket
    function cancelApproval(address robot, uint256 amount) external {
        _cancel(keccak256(abi.encode(robot, amount)), robot);
    }

    /// @inheritdoc IInformationMarket
    function cancelRevocation(address robot) external {
        _cancel(keccak256(abi.encode("revoke", robot, _exits[robot].reinstated)), robot);
    }

    function _cancel(bytes32 request, address robot) internal {
        if (!_stands(msg.sender, _approvedAt[request][msg.sender])) {
            revert InfoMarketNotApproved(msg.sender, robot);
        }
        _approvedAt[request][msg.sender] = _CANCELLED;
        emit ApprovalCancelled(msg.sender, robot, request);
    }

    /// @inheritdoc IInformationMarket
    function approvals(address robot, uint256 amount) external view returns (uint256) {
        return _standing(keccak256(abi.encode(robot, amount)));
    }

    /// @inheritdoc IInformationMarket
    function isRegistered(address robot) external view returns (bool) {
        return _registered[robot];
    }

    /// @inheritdoc IInformationMarket
    function bondOf(address robot) external view returns (uint256) {
        return _registered[robot] || _exits[robot].state == _EXITING ? _registrationBond : 0;
    }

    /// @dev Records the caller's approval of `request` about `robot`, within its quota; returns how many
    /// approvals of it stand. A registrar whose approval stands may not approve again; one whose approval
    /// lapsed, was cancelled or predates its role may.
    function _approve(bytes32 request, address robot) internal returns (uint256) {
        uint256 at = _approvedAt[request][msg.sender];
        if (at == 0) _approvers[request].push(msg.sender);
        else if (_stands(msg.sender, at)) revert InfoMarketAlreadyApproved(msg.sender, robot);
        uint256 used = _quotaUsed[msg.sender];
        uint256 slot = used % _registrarQuota;
        if (used >= _registrarQuota && uint256(_quotaBlocks[msg.sender][slot]) + _registrarPeriod > block.number) {
            revert InfoMarketRegistrarQuotaExceeded(msg.sender, _registrarQuota);
        }
        _quotaBlocks[msg.sender][slot] = uint64(block.number);
        _quotaUsed[msg.sender] = used + 1;
        _approvedAt[request][msg.sender] = (_roleGrants[REGISTRAR_ROLE][msg.sender] << 64) | block.number;
        return _standing(request);
    }

    /// @dev How many approvals of `request` stand (one per registrar key that approved it).
    function _standing(bytes32 request) internal view returns (uint256 count) {
        address[] storage list = _approvers[request];
        for (uint256 i; i < list.length; ++i) {
            if (_stands(list[i], _approvedAt[request][list[i]])) ++count;
        }
    }

    /// @dev Whether `registrar`'s approval `at` ((grants << 64) | block) stands: given and not withdrawn,
    /// while the key holds the registrar role under the grant it approved under, less than
    /// `registrarPeriod` blocks ago.
    function _stands(address registrar, uint256 at) internal view returns (bool) {
        return at != 0 && at != _CANCELLED && _roles[REGISTRAR_ROLE][registrar]
            && at >> 64 == _roleGrants[REGISTRAR_ROLE][registrar] && (at & type(uint64).max) + _registrarPeriod > block.number;
    }
}
