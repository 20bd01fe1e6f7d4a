"""The paper's open questions (issue 10): reputation-aware defences against attacks that target them."""
