"""The paper's open questions: reputation-aware defences against attacks that target them."""
