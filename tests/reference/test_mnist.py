"""The MNIST experiment's tSNE (bhtsne, Barnes–Hut) against scikit-learn's on the same
latent codes: both embeddings are scored by the same exact KL divergence (scikit-learn's
joint probabilities at perplexity 30 and its `_kl_divergence`), so the check is on the
quality of the result, not on either library's own cost estimate."""
import os
from pathlib import Path

import numpy as np
from scipy.spatial.distance import pdist, squareform
from sklearn.manifold import TSNE
from sklearn.manifold._t_sne import _joint_probabilities, _kl_divergence

from conftest import ROOT, run

MNIST = Path(os.environ.get("VF_SHARED_MNIST", ROOT.parent / "shared" / "mnist"))


def exact_kl(codes, embedding, perplexity):
    p = _joint_probabilities(squareform(pdist(codes, "sqeuclidean")), perplexity, 0)
    kl, _ = _kl_divergence(embedding.astype(np.float64).ravel(), p, 1, codes.shape[0], 2)
    return kl


def test_tsne_is_as_good_as_scikit_learn_on_the_same_codes(tmp_path):
    out = tmp_path / "m"
    # A small encoder is enough to give structured codes.
    run("mnist", "train", "--quick", "--quiet", "--methods", "voronoi", "--images", "300", "--epochs", "1",
        "--data", MNIST, "--out", out)
    run("mnist", "tsne", "--quick", "--quiet", "--methods", "voronoi", "--count", "1000", "--iterations", "1000",
        "--data", MNIST, "--out", out)
    z = np.load(out / "tsne_voronoi.npz")
    codes = z["codes"].reshape(-1, 16).astype(np.float64)
    ours = z["embedding"].reshape(-1, 2)
    labels = z["labels"]
    assert codes.shape == (1000, 16) and ours.shape == (1000, 2) and labels.shape == (1000,)
    assert np.isfinite(ours).all()
    theirs = TSNE(n_components=2, perplexity=30.0, init="random", method="barnes_hut", angle=0.5,
                  max_iter=1000, random_state=0).fit_transform(codes)
    kl_ours = exact_kl(codes, ours, 30.0)
    kl_theirs = exact_kl(codes, theirs, 30.0)
    print(f"exact KL: bhtsne {kl_ours:.4f}, scikit-learn {kl_theirs:.4f}")
    assert kl_ours <= 1.10 * kl_theirs + 0.02, (kl_ours, kl_theirs)
    # The same embedding is not a random one: a random layout scores far worse.
    rng = np.random.default_rng(0)
    assert exact_kl(codes, rng.normal(size=ours.shape), 30.0) > 1.5 * kl_ours
