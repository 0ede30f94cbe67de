// The MPI layer's decisions that need no MPI: which Open MPI parameters a run on one node
// sets before MPI_Init (mpi::single_node_mca).
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "mpi/mpi.hpp"

namespace {

using superball::mpi::Getenv;
using superball::mpi::McaSetting;
using superball::mpi::single_node_mca;
using Settings = std::vector<McaSetting>;

// An environment holding exactly `vars`.
Getenv environment(const std::map<std::string, std::string>& vars)
{
    return [vars](const char* name) -> const char* {
        const auto it = vars.find(name);
        return it == vars.end() ? nullptr : it->second.c_str();
    };
}

const McaSetting ob1{"pml", "ob1"};
const McaSetting isolated{"ess_singleton_isolated", "1"};
const std::map<std::string, std::string> mpirun_one_node{
    {"OMPI_COMM_WORLD_SIZE", "2"}, {"OMPI_COMM_WORLD_LOCAL_SIZE", "2"}, {"PMIX_RANK", "1"}};

TEST(SingleNodeMca, SingletonGetsOb1WithoutADaemon)
{
    EXPECT_EQ(single_node_mca(environment({{"HOME", "/root"}, {"PATH", "/usr/bin"}}), ""), (Settings{ob1, isolated}));
    // Inside a Slurm allocation but started without srun: still a singleton.
    EXPECT_EQ(single_node_mca(environment({{"SLURM_JOB_ID", "12"}, {"SLURM_NNODES", "4"}}), ""),
              (Settings{ob1, isolated}));
}

TEST(SingleNodeMca, MpirunOnOneNodeGetsOb1)
{
    EXPECT_EQ(single_node_mca(environment(mpirun_one_node), ""), Settings{ob1});
}

TEST(SingleNodeMca, SeveralNodesKeepOpenMpisChoice)
{
    EXPECT_EQ(single_node_mca(environment({{"OMPI_COMM_WORLD_SIZE", "64"}, {"OMPI_COMM_WORLD_LOCAL_SIZE", "32"},
                                           {"PMIX_RANK", "3"}}),
                              ""),
              Settings{});
    EXPECT_EQ(single_node_mca(environment({{"OMPI_COMM_WORLD_SIZE", "64"}}), ""), Settings{});
}

TEST(SingleNodeMca, OtherLaunchersKeepOpenMpisChoice)
{
    // srun (PMIx or PMI-2) and MPICH's hydra say nothing here about the number of nodes.
    for (const char* var : {"PMIX_RANK", "PMI_RANK", "PMI_SIZE", "PMI_FD"}) {
        EXPECT_EQ(single_node_mca(environment({{var, "0"}}), ""), Settings{}) << var;
    }
}

TEST(SingleNodeMca, TheUsersChoiceIsNeverReplaced)
{
    for (const char* value : {"ucx", "cm", "^ucx", ""}) {
        EXPECT_EQ(single_node_mca(environment({{"OMPI_MCA_pml", value}}), ""), Settings{isolated}) << value;
        auto vars = mpirun_one_node;
        vars["OMPI_MCA_pml"] = value;
        EXPECT_EQ(single_node_mca(environment(vars), ""), Settings{}) << value;
    }
    EXPECT_EQ(single_node_mca(environment({{"OMPI_MCA_ess_singleton_isolated", "0"}}), ""), Settings{ob1});
    EXPECT_EQ(single_node_mca(environment({{"OMPI_MCA_mca_base_param_files", "/etc/site.conf"}}), ""), Settings{});
    // ~/.openmpi/mca-params.conf
    EXPECT_EQ(single_node_mca(environment({}), "# site defaults\nbtl = self,vader,tcp\n  pml\t= ucx  # fast\n"),
              Settings{isolated});
    EXPECT_EQ(single_node_mca(environment({}), "btl = self,vader\n# pml = ucx\npml_ucx_verbose = 1\n"),
              (Settings{ob1, isolated}));
}

TEST(SingleNodeMca, NoChoiceOfTheFileLayersIsMade)
{
    // superball writes its files with POSIX calls and serial HDF5 (io/partial_file.hpp):
    // MPI-IO's components are the user's business.
    EXPECT_EQ(single_node_mca(environment(mpirun_one_node), "io = romio321\n"), Settings{ob1});
    EXPECT_EQ(single_node_mca(environment(mpirun_one_node), "fcoll = vulcan\n"), Settings{ob1});
}

}  // namespace
